//! The streaming form of `needle eval --poses FILE` (CSV out): the file is read in chunks
//! of [`CHUNK_ROWS`] records; each chunk is parsed, evaluated and formatted on every core
//! (one slice per thread, written in input order) while the main thread writes the one
//! before and splits the next one, so memory stays bounded (two chunks of records and two
//! of text) however long the file is. The rows and messages are those of [`batch`](super::batch): the
//! same parse ([`parse_row`]), the same output bytes (the floats through
//! [`float_text::push_f32`](crate::output::float_text::push_f32), `{:?}`'s text), the problems
//! listed in line order.
//!
//! Nothing is written when a row is bad: the output goes to a temporary renamed at the
//! end (`--out`), or, for standard output, the file is checked in a first pass before
//! the second one writes.
use super::batch::{bad_rows_error, parse_row, pose_columns, OUTPUT_HEADER};
use crate::output::float_text::push_f32;
use anyhow::{Context, Result};
use needle_haptics::{wrench, Pose};
use std::io::Write;
use std::path::Path;

/// Records per chunk (65,536: about 2.4 MB of input, 7 MB of output text).
pub const CHUNK_ROWS: usize = 1 << 16;

/// One chunk as the reader split it: its records (the first `len` of `records`, reused
/// from chunk to chunk) and the problems of records it could not read (line, message).
#[derive(Default)]
struct Chunk {
    records: Vec<csv::ByteRecord>,
    len: usize,
    unreadable: Vec<(u64, String)>,
}

/// What a thread made of its slice of a chunk: the rows parsed, bad rows, problems
/// (line, message), and the formatted output when every row was good.
#[derive(Default)]
struct Slice {
    rows: usize,
    bad_rows: usize,
    problems: Vec<(u64, String)>,
    text: String,
}

/// Reads `file` chunk by chunk; with `sink` evaluates and writes every row (the header
/// first), without it only checks the rows. Returns the number of rows.
///
/// # Errors
/// The file cannot be read, a bad header, bad rows (counted, the first listed in line
/// order; the writes stop at the first chunk with one), or the output cannot be written.
pub fn stream(file: &Path, mut sink: Option<&mut dyn Write>) -> Result<usize> {
    let mut rdr = csv::ReaderBuilder::new()
        // the fields are trimmed by `parse_row` (csv's field trimming allocates a record
        // per row: 8 % of the run)
        .trim(csv::Trim::Headers)
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
    // the slices of the chunk the workers take and of the one before it (written while
    // the workers take this one)
    let mut slices: Vec<Slice> = (0..threads).map(|_| Slice::default()).collect();
    let mut written: Vec<Slice> = (0..threads).map(|_| Slice::default()).collect();
    let (mut current, mut next) = (Chunk::default(), Chunk::default());
    let (mut rows, mut bad_rows, mut problems) = (0usize, 0usize, Vec::new());
    let mut more = read_chunk(&mut rdr, file, &mut current);
    loop {
        let write = sink.is_some() && bad_rows == 0;
        // the workers take this chunk while this thread writes the one before (every
        // row good so far) and splits the next one
        let wrote = std::thread::scope(|scope| {
            let per = current.len.div_ceil(threads).max(1);
            let mut parts = current.records.get(..current.len).unwrap_or(&[]).chunks(per);
            for slice in &mut slices {
                let part = parts.next().unwrap_or(&[]);
                let idx = &idx;
                scope.spawn(move || process(part, idx, file, write, slice));
            }
            let wrote = write_slices(sink.as_deref_mut().filter(|_| write), &written);
            if more {
                more = read_chunk(&mut rdr, file, &mut next);
            } else {
                next.len = 0;
                next.unreadable.clear();
            }
            wrote
        });
        wrote?;
        bad_rows += current.unreadable.len();
        problems.append(&mut current.unreadable);
        for slice in &mut slices {
            rows += slice.rows;
            bad_rows += slice.bad_rows;
            problems.append(&mut slice.problems);
        }
        std::mem::swap(&mut slices, &mut written);
        std::mem::swap(&mut current, &mut next);
        if current.len == 0 && current.unreadable.is_empty() {
            break;
        }
    }
    write_slices(sink.filter(|_| bad_rows == 0), &written)?;
    if bad_rows > 0 {
        problems.sort_by_key(|(line, _)| *line);
        let listed: Vec<String> = problems.into_iter().map(|(_, p)| p).collect();
        return Err(bad_rows_error(bad_rows, &listed));
    }
    Ok(rows)
}

/// The text of `slices` in order to `sink` (none: nothing).
fn write_slices<W: Write + ?Sized>(sink: Option<&mut W>, slices: &[Slice]) -> Result<()> {
    if let Some(w) = sink {
        for slice in slices {
            w.write_all(slice.text.as_bytes()).context("writing the output")?;
        }
    }
    Ok(())
}

/// Splits up to [`CHUNK_ROWS`] records into `chunk`; whether the file may have more.
fn read_chunk(rdr: &mut csv::Reader<std::fs::File>, file: &Path, chunk: &mut Chunk) -> bool {
    chunk.len = 0;
    chunk.unreadable.clear();
    while chunk.len < CHUNK_ROWS {
        if chunk.records.len() <= chunk.len {
            chunk.records.push(csv::ByteRecord::new());
        }
        let Some(rec) = chunk.records.get_mut(chunk.len) else { return false };
        match rdr.read_byte_record(rec) {
            Ok(false) => return false,
            Ok(true) => chunk.len += 1,
            Err(e) => {
                let line = e.position().map_or(0, csv::Position::line);
                chunk.unreadable.push((line, format!("{}:{line}: {e}", file.display())));
            }
        }
    }
    true
}

/// Parses `records` (pose columns `idx`); with `write` and every row good, evaluates
/// and formats them (each its inputs, wrench and status: `batch`'s row) into
/// `out.text`.
fn process(records: &[csv::ByteRecord], idx: &[usize; 5], file: &Path, write: bool, out: &mut Slice) {
    out.rows = 0;
    out.bad_rows = 0;
    out.problems.clear();
    out.text.clear();
    let mut poses = Vec::with_capacity(records.len());
    let mut messages = Vec::new();
    for rec in records {
        let line = rec.position().map_or(0, csv::Position::line);
        match parse_row(|i| rec.get(i), rec.len(), idx, (file, line), &mut messages) {
            Some(p) => poses.push(p),
            None => out.bad_rows += 1,
        }
        out.problems.extend(messages.drain(..).map(|m| (line, m)));
    }
    out.rows = poses.len();
    if write && out.bad_rows == 0 {
        format_rows(&poses, &mut out.text);
    }
}

/// The rows of `poses` appended to `text`.
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
        Some(path) => needle_stdx::fs::write_atomic_streamed(path, |w| stream(file, Some(w))),
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
