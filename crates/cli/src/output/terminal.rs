//! [`Terminal`]: where the library crates' text goes in the `needle` command
//! ([`needle_stdx::report`]): their output to stdout, their progress and warnings to
//! stderr, as written (only the CLI prints; docs/architecture.md).

/// The `needle` command's [`needle_stdx::report::Sink`]: stdout and stderr.
pub struct Terminal;

impl needle_stdx::report::Sink for Terminal {
    fn out(&self, text: &str) {
        print!("{text}");
    }

    fn note(&self, text: &str) {
        eprint!("{text}");
    }
}

/// Installs [`Terminal`] as the process's sink (once; later calls change nothing).
pub fn install() {
    needle_stdx::report::set_sink(&Terminal);
}
