//! The `golden` firmware's fixed-point section against the set's `golden-fixed.csv`:
//! inputs, status and every wrench integer exactly.
use super::comparison::Comparison;
use anyhow::bail;

/// The fixed-point golden file's header line.
pub const HEADER: &str = crate::fit::golden_fixed::HEADER;

/// Compares the fixed-point section of the `golden` firmware's stdout `output` (after its
/// `needle-golden-fixed rows=N` line) with the text `csv` of golden-fixed.csv.
///
/// # Errors
/// The section is missing, truncated or malformed, or holds another number of rows;
/// differing values are [`Comparison::mismatches`].
pub fn compare(output: &str, csv: &str) -> anyhow::Result<Comparison> {
    let mut want = csv.lines();
    if want.next() != Some(HEADER) {
        bail!("golden-fixed.csv: the first line is not the header {HEADER:?}");
    }
    let want: Vec<&str> = want.collect();
    let mut got = output.lines().skip_while(|l| !l.starts_with("needle-golden-fixed rows="));
    let banner = got.next().unwrap_or_default().to_string();
    if banner.is_empty() {
        bail!("the firmware printed no fixed-point section (no `needle-golden-fixed rows=` line)");
    }
    if banner != format!("needle-golden-fixed rows={}", want.len()) {
        bail!("the firmware holds another number of fixed-point poses than golden-fixed.csv's {}: {banner:?}", want.len());
    }
    let mut mismatches = Vec::new();
    for (i, w) in want.iter().enumerate() {
        let line = i + 2;
        let Some(g) = got.next() else {
            bail!("the firmware's fixed-point output stops before golden-fixed line {line}");
        };
        let wf: Vec<&str> = w.split(',').collect();
        let gf: Vec<&str> = g.split(',').collect();
        if wf.len() != 12 || gf.len() != 12 {
            bail!("golden-fixed line {line}: {} fields in the file, {} from the firmware ({g:?}); expected 12", wf.len(), gf.len());
        }
        if wf[..5] != gf[..5] {
            bail!("firmware row for golden-fixed line {line} has other inputs: {g:?} (golden {w:?})");
        }
        let diffs: Vec<String> = (5..12)
            .filter(|&c| wf[c] != gf[c])
            .map(|c| format!("{} want {} got {}", HEADER.split(',').nth(c).unwrap_or("?"), wf[c], gf[c]))
            .collect();
        if !diffs.is_empty() {
            mismatches.push(format!("line {line} (pose {}): {}", wf[..5].join(","), diffs.join("; ")));
        }
    }
    let end = got.next().unwrap_or_default();
    if end != format!("needle-golden-fixed end rows={}", want.len()) {
        bail!("the firmware's fixed-point output does not end with its end line: {end:?}");
    }
    Ok(Comparison { banner, rows: want.len(), mismatches })
}
