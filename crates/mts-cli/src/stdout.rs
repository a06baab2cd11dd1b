//! Standard output that fails like a Unix tool: [`outln!`] and [`out!`]
//! return an error instead of panicking as `println!` does.
//!
//! A closed pipe (`mts info m.mts | head -c 0`) ends the command quietly:
//! the error is [`ClosedPipe`], which `main` turns into exit status 141
//! (128 + SIGPIPE, what a shell reports for a tool the signal ended) with
//! nothing on standard error. Any other failure (`> /dev/full`) is an
//! ordinary error naming standard output.

use std::io::Write;

/// Standard output's reader went away: the command stops, saying nothing.
#[derive(Debug)]
pub struct ClosedPipe;

impl std::fmt::Display for ClosedPipe {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("standard output was closed")
    }
}

impl std::error::Error for ClosedPipe {}

/// Writes `args` to standard output and flushes it, mapping a failure to
/// [`ClosedPipe`] or to an error naming standard output.
pub fn write(args: std::fmt::Arguments<'_>) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_fmt(args)
        .and_then(|()| out.flush())
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::BrokenPipe => anyhow::Error::new(ClosedPipe),
            _ => anyhow::Error::new(e).context("cannot write to standard output"),
        })
}

/// `println!` that returns `anyhow::Result<()>` (see the module docs).
macro_rules! outln {
    () => {
        $crate::stdout::write(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::stdout::write(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `print!` that returns `anyhow::Result<()>` (see the module docs).
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::stdout::write(format_args!($($arg)*))
    };
}

/// `eprintln!` for notes and warnings: a closed or full standard error is
/// not worth failing a command over (`eprintln!` would panic).
macro_rules! warnln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

pub(crate) use {out, outln, warnln};
