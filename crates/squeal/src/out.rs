//! Standard output that behaves like a Unix tool's: a reader that went away
//! (`squeal stability | head -1`) ends squeal quietly with exit code 0; any
//! other write error (`> /dev/full`) ends it with one line and exit code 1.
//! `println!` would panic on both.

use std::io::Write;

/// `println!` for standard output, through [`line()`].
#[macro_export]
macro_rules! outln {
    () => {
        $crate::out::line(format_args!(""))
    };
    ($($t:tt)*) => {
        $crate::out::line(format_args!($($t)*))
    };
}

/// Write one line to standard output (see the module's rules on errors).
pub fn line(args: std::fmt::Arguments) {
    let mut o = std::io::stdout().lock();
    let r = o
        .write_fmt(args)
        .and_then(|_| o.write_all(b"\n"))
        .and_then(|_| o.flush());
    if let Err(e) = r {
        fail(e);
    }
}

/// Write text as it is to standard output.
pub fn text(s: &str) {
    let mut o = std::io::stdout().lock();
    if let Err(e) = o.write_all(s.as_bytes()).and_then(|_| o.flush()) {
        fail(e);
    }
}

fn fail(e: std::io::Error) -> ! {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        std::process::exit(0);
    }
    err_line(format_args!("error: cannot write to standard output: {e}"));
    std::process::exit(1);
}

/// `eprintln!` for standard error, through [`err_line()`]: never panics.
#[macro_export]
macro_rules! errln {
    ($($t:tt)*) => {
        $crate::out::err_line(format_args!($($t)*))
    };
}

/// Write one line to standard error, as a terminal may show it
/// ([`squeal_study::error::for_terminal`]: control characters escaped, cut
/// to a sane length). A failed write (`2>/dev/full`, a closed stderr) is
/// ignored: the run ends with its own exit code (issue 24, class 5).
pub fn err_line(args: std::fmt::Arguments) {
    squeal_files::error::note(args);
}

/// Text to standard error as it is (clap's help on a missing subcommand),
/// ignoring a failed write.
pub fn err_text(s: &str) {
    let _ = std::io::stderr().lock().write_all(s.as_bytes());
}
