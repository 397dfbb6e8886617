//! What the library crates say, and who prints it: **only the CLI prints**
//! (docs/architecture.md; the host test `only_the_cli_prints`). A library crate does not
//! write to the terminal; what it has to say while it works (a campaign's table, a
//! build's "building ...", a check's lines) goes through this facade, as a library logs
//! through the `log` crate: [`out`] for the command's output (stdout), [`note`] for
//! progress and warnings (stderr), or the macros [`outln!`](crate::outln),
//! [`out!`](crate::out), [`noteln!`](crate::noteln), [`note!`](crate::note). The binary
//! owns the terminal: it installs a [`Sink`] once ([`set_sink`]; the `needle` command's
//! prints both as they are). Without a sink (a library used alone, a test) nothing is
//! printed.

use std::sync::OnceLock;

/// Where the library crates' text goes; installed by the binary ([`set_sink`]).
pub trait Sink: Send + Sync {
    /// The command's output, as written (newlines included).
    fn out(&self, text: &str);
    /// Progress and warnings, as written (newlines included).
    fn note(&self, text: &str);
}

static SINK: OnceLock<&'static dyn Sink> = OnceLock::new();

/// Installs the process's sink. The first call wins: returns whether `sink` is the one
/// installed.
pub fn set_sink(sink: &'static dyn Sink) -> bool {
    SINK.set(sink).is_ok()
}

/// The command's output `text` to the sink, if any.
pub fn out(text: &str) {
    if let Some(s) = SINK.get() {
        s.out(text);
    }
}

/// Progress or a warning, `text`, to the sink, if any.
pub fn note(text: &str) {
    if let Some(s) = SINK.get() {
        s.note(text);
    }
}

/// [`out`] of the formatted text, as `print!`.
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => { $crate::report::out(&::std::format!($($arg)*)) };
}

/// [`out`] of the formatted text and a newline, as `println!`.
#[macro_export]
macro_rules! outln {
    () => { $crate::report::out("\n") };
    ($($arg:tt)*) => { $crate::report::out(&::std::format!("{}\n", ::std::format_args!($($arg)*))) };
}

/// [`note`] of the formatted text, as `eprint!`.
#[macro_export]
macro_rules! note {
    ($($arg:tt)*) => { $crate::report::note(&::std::format!($($arg)*)) };
}

/// [`note`] of the formatted text and a newline, as `eprintln!`.
#[macro_export]
macro_rules! noteln {
    () => { $crate::report::note("\n") };
    ($($arg:tt)*) => { $crate::report::note(&::std::format!("{}\n", ::std::format_args!($($arg)*))) };
}

#[cfg(test)]
mod tests {
    use std::sync::Mutex;

    struct Keep(Mutex<Vec<String>>);
    impl super::Sink for Keep {
        fn out(&self, text: &str) {
            self.0.lock().expect("lock").push(format!("out {text}"));
        }
        fn note(&self, text: &str) {
            self.0.lock().expect("lock").push(format!("note {text}"));
        }
    }

    #[test]
    fn the_sink_installed_first_gets_the_text() {
        static KEEP: Keep = Keep(Mutex::new(Vec::new()));
        static OTHER: Keep = Keep(Mutex::new(Vec::new()));
        crate::outln!("a {}", 1);
        assert!(super::set_sink(&KEEP), "the first sink");
        assert!(!super::set_sink(&OTHER), "one sink per process");
        crate::outln!("b {}", 2);
        crate::out!("c");
        crate::noteln!("d");
        crate::note!("e {:.1}", 0.25);
        let got = KEEP.0.lock().expect("lock").clone();
        assert_eq!(got, ["out b 2\n", "out c", "note d\n", "note e 0.2"]);
        assert!(OTHER.0.lock().expect("lock").is_empty());
    }
}
