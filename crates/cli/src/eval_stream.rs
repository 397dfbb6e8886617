//! The streaming form of `needle eval --poses FILE` (CSV out): the file is read in chunks
//! of [`CHUNK_ROWS`] rows, each chunk evaluated and formatted on every core (one slice
//! per thread, written in input order), so memory stays bounded (a few chunks of rows
//! and their text) however long the file is. The rows and messages are those of
//! [`eval_batch`](super::eval_batch): the same parse, the same output bytes (the floats
//! through [`float_text::push_f32`](super::float_text::push_f32), `{:?}`'s text).
//!
//! Nothing is written when a row is bad: the output goes to a temporary renamed at the
//! end (`--out`), or, for standard output, the file is checked in a first pass before
//! the second one writes.
use super::eval_batch::{bad_rows_error, parse_row, pose_columns, OUTPUT_HEADER};
use super::float_text::push_f32;
use anyhow::{Context, Result};
use needle_haptics::{wrench, Pose};
use std::io::Write;
use std::path::Path;

/// Rows per chunk (65,536: about 2.4 MB of input, 7 MB of output text).
pub const CHUNK_ROWS: usize = 1 << 16;

/// Reads `file` chunk by chunk; with `sink` evaluates and writes every row (the header
/// first), without it only checks the rows. Returns the number of rows.
///
/// # Errors
/// The file cannot be read, a bad header, bad rows (counted, the first listed; the
/// writes stop at the first), or the output cannot be written.
pub fn stream(file: &Path, mut sink: Option<&mut dyn Write>) -> Result<usize> {
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .flexible(true)
        .buffer_capacity(1 << 20)
        .from_path(file)
        .with_context(|| format!("{}: cannot read", file.display()))?;
    let header = rdr.headers().with_context(|| format!("{}:1: cannot read the header", file.display()))?.clone();
    let idx = pose_columns(&header, file)?;
    if let Some(w) = sink.as_deref_mut() {
        writeln!(w, "{OUTPUT_HEADER}").context("writing the output")?;
    }
    let threads = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
    let mut texts: Vec<String> = vec![String::new(); threads];
    let (mut rows, mut bad_rows, mut problems) = (0usize, 0usize, Vec::new());
    let mut rec = csv::ByteRecord::new();
    let mut chunk: Vec<Pose> = Vec::with_capacity(CHUNK_ROWS);
    loop {
        chunk.clear();
        let mut more = true;
        while chunk.len() < CHUNK_ROWS {
            match rdr.read_byte_record(&mut rec) {
                Ok(false) => {
                    more = false;
                    break;
                }
                Ok(true) => {
                    let line = rec.position().map_or(0, csv::Position::line);
                    match parse_row(|i| rec.get(i), rec.len(), &idx, (file, line), &mut problems) {
                        Some(p) => chunk.push(p),
                        None => bad_rows += 1,
                    }
                }
                Err(e) => {
                    let line = e.position().map_or(0, csv::Position::line);
                    problems.push(format!("{}:{line}: {e}", file.display()));
                    bad_rows += 1;
                }
            }
        }
        rows += chunk.len();
        if bad_rows == 0 {
            if let Some(w) = sink.as_deref_mut() {
                format_chunk(&chunk, &mut texts);
                for t in &texts {
                    w.write_all(t.as_bytes()).context("writing the output")?;
                }
            }
        }
        if !more {
            break;
        }
    }
    if bad_rows > 0 {
        return Err(bad_rows_error(bad_rows, &problems));
    }
    Ok(rows)
}

/// Evaluates and formats `chunk` into `texts` (one slice of the chunk per text, in
/// order), each on its own thread.
fn format_chunk(chunk: &[Pose], texts: &mut [String]) {
    let per = chunk.len().div_ceil(texts.len().max(1)).max(1);
    std::thread::scope(|scope| {
        let mut slices = chunk.chunks(per);
        for text in texts.iter_mut() {
            let slice = slices.next().unwrap_or(&[]);
            text.clear();
            scope.spawn(move || format_rows(slice, text));
        }
    });
}

/// The rows of `poses` (each its inputs, wrench and status: `eval_batch`'s row) appended
/// to `text`.
fn format_rows(poses: &[Pose], text: &mut String) {
    let mut ryu = ryu::Buffer::new();
    text.reserve(poses.len() * 150);
    for p in poses {
        let e = wrench(p);
        for v in [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg, p.depth_mm].into_iter().chain(e.wrench.to_array()) {
            push_f32(text, v, &mut ryu);
            text.push(',');
        }
        let status = e.status.bits();
        text.push_str("0x");
        for nibble in [status >> 4, status & 0xf] {
            text.push(char::from_digit(u32::from(nibble), 16).unwrap_or('0'));
        }
        text.push('\n');
    }
}

/// `needle eval --poses FILE` in CSV: to `out` (a temporary renamed at the end) or to
/// standard output (after a first pass that checks every row). Returns the rows.
///
/// # Errors
/// As [`stream`]; nothing is written then.
pub fn eval_csv(file: &Path, out: Option<&Path>) -> Result<usize> {
    match out {
        Some(path) => needle_fe::results::write_atomic_streamed(path, |w| stream(file, Some(w))),
        None => {
            stream(file, None)?;
            let stdout = std::io::stdout();
            let mut w = std::io::BufWriter::with_capacity(1 << 20, stdout.lock());
            let rows = stream(file, Some(&mut w))?;
            w.flush().context("writing to standard output")?;
            Ok(rows)
        }
    }
}
