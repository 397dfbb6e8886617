//! The outcome of comparing a firmware run with a golden file (f32 and fixed point).

/// Result of comparing one firmware run with the golden file.
#[derive(Debug)]
pub struct Comparison {
    /// The firmware's first line (target, set, fe_sha256, rows).
    pub banner: String,
    /// Rows compared.
    pub rows: usize,
    /// Rows that differ, one description each (`line N: ...`, line of the golden file).
    pub mismatches: Vec<String>,
}

/// `true` when the golden bits `want` and the printed `got` are the same value under the
/// contract: NaN matches NaN of any payload, anything else compares by bits.
#[must_use]
pub fn same_f32(want: u32, got: u32) -> bool {
    if f32::from_bits(want).is_nan() {
        f32::from_bits(got).is_nan()
    } else {
        want == got
    }
}

/// One extra section of the `golden` firmware's output: a `<tag> rows=N` line, N rows in
/// the golden file's format, then `<tag> end rows=N<end_suffix>`.
pub struct Section<'a> {
    /// The golden file's name, for messages.
    pub file: &'a str,
    /// The section's line prefix (`needle-golden-fixed`).
    pub tag: &'a str,
    /// The golden file's header line.
    pub header: &'a str,
    /// Fields per row (the first five are the pose).
    pub fields: usize,
    /// What the end line carries after `rows=N` (a firmware-side count that must be 0).
    pub end_suffix: &'a str,
}

impl Section<'_> {
    /// Compares the section in the firmware's stdout `output` with the golden file's
    /// text `csv`; `row(line, want, got)` lists the differences of one row whose pose
    /// fields agree (`line` the golden file's 1-based line).
    ///
    /// # Errors
    /// The header is not the golden file's first line; the section is missing, truncated
    /// or malformed, holds another number of rows or another pose, or `row` fails.
    pub fn compare(
        &self,
        output: &str,
        csv: &str,
        row: impl Fn(usize, &[&str], &[&str]) -> anyhow::Result<Vec<String>>,
    ) -> anyhow::Result<Comparison> {
        let Self { file, tag, header, fields, end_suffix } = self;
        let mut want = csv.lines();
        if want.next() != Some(*header) {
            anyhow::bail!("{file}: the first line is not the header {header:?}");
        }
        let want: Vec<&str> = want.collect();
        let start = format!("{tag} rows=");
        let mut got = output.lines().skip_while(|l| !l.starts_with(&start));
        let Some(banner) = got.next().map(str::to_string) else {
            anyhow::bail!("the firmware printed no `{start}` section for {file}");
        };
        if banner != format!("{start}{}", want.len()) {
            anyhow::bail!("the firmware holds another number of poses than {file}'s {}: {banner:?}", want.len());
        }
        let mut mismatches = Vec::new();
        for (i, w) in want.iter().enumerate() {
            let line = i + 2;
            let Some(g) = got.next() else {
                anyhow::bail!("the firmware's `{tag}` output stops before {file} line {line}");
            };
            let wf: Vec<&str> = w.split(',').collect();
            let gf: Vec<&str> = g.split(',').collect();
            if wf.len() != *fields || gf.len() != *fields {
                anyhow::bail!(
                    "{file} line {line}: {} fields in the file, {} from the firmware ({g:?}); expected {fields}",
                    wf.len(),
                    gf.len()
                );
            }
            if wf.get(..5) != gf.get(..5) {
                anyhow::bail!("firmware row for {file} line {line} has other inputs: {g:?} (golden {w:?})");
            }
            let diffs = row(line, &wf, &gf)?;
            if !diffs.is_empty() {
                mismatches.push(format!("line {line} (pose {}): {}", wf.get(..5).unwrap_or_default().join(","), diffs.join("; ")));
            }
        }
        let want_end = format!("{tag} end rows={}{end_suffix}", want.len());
        let end = got.next().unwrap_or_default();
        if end != want_end {
            anyhow::bail!("the firmware's `{tag}` output does not end with {want_end:?}: {end:?}");
        }
        Ok(Comparison { banner, rows: want.len(), mismatches })
    }
}
