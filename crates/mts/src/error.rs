//! Errors of the `mts` library.
//!
//! User-input errors (a file that cannot be read or parsed, a mesh that is
//! unusable) are kept apart from broken internal invariants, which are
//! `assert!`s and never reach this type.

use std::fmt;
use std::path::PathBuf;

/// Where in an input a problem was found: any of line, byte offset, element
/// and element index that is known.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Place {
    /// 1-based line number (text formats and headers).
    pub line: Option<u64>,
    /// Byte offset from the start of the file (binary formats).
    pub byte: Option<u64>,
    /// The element being read, e.g. `vertex`, `face`, `tristrips`, `v`, `f`.
    pub element: Option<String>,
    /// 0-based index of that element.
    pub index: Option<u64>,
}

impl Place {
    /// A place known by its 1-based line.
    #[must_use]
    pub fn line(line: u64) -> Place {
        Place {
            line: Some(line),
            ..Place::default()
        }
    }

    /// A place known by element name and index.
    #[must_use]
    pub fn element(element: &str, index: u64) -> Place {
        Place {
            element: Some(element.to_owned()),
            index: Some(index),
            ..Place::default()
        }
    }

    /// This place with a line number added.
    #[must_use]
    pub fn at_line(mut self, line: u64) -> Place {
        self.line = Some(line);
        self
    }

    /// This place with a byte offset added.
    #[must_use]
    pub fn at_byte(mut self, byte: u64) -> Place {
        self.byte = Some(byte);
        self
    }
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        if let Some(l) = self.line {
            parts.push(format!("line {l}"));
        }
        if let Some(b) = self.byte {
            parts.push(format!("byte {b}"));
        }
        match (&self.element, self.index) {
            (Some(e), Some(i)) => parts.push(format!("{e} {i}")),
            (Some(e), None) => parts.push(e.clone()),
            (None, Some(i)) => parts.push(format!("index {i}")),
            (None, None) => {}
        }
        if parts.is_empty() {
            f.write_str("whole file")
        } else {
            f.write_str(&parts.join(", "))
        }
    }
}

/// Everything that can go wrong in the library.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The file could not be opened or read.
    #[error("{}: {source}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// The file's content is malformed at a known place.
    #[error("{}: {place}: {message}", file.display())]
    Parse {
        /// The file (or `<memory>` for in-memory input).
        file: PathBuf,
        /// Where the problem is.
        place: Place,
        /// What is wrong there.
        message: String,
    },
    /// The file's format is not one this crate reads.
    #[error("{}: unknown format: {message}", file.display())]
    UnknownFormat {
        /// The file.
        file: PathBuf,
        /// Why it was not recognised.
        message: String,
    },
    /// The mesh is unusable as a whole (no triangles left, too many vertices).
    #[error("{}: {message}", source_name)]
    InvalidMesh {
        /// The file or generator the mesh came from.
        source_name: String,
        /// What is wrong.
        message: String,
    },
    /// An argument is outside its documented domain.
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// No graphics adapter could be found (no GPU and no software driver
    /// such as Mesa's lavapipe): callers that can do without rendering
    /// (tests, benches) skip on this one.
    #[error("no graphics adapter: {0}")]
    NoAdapter(String),
    /// A structure's invariant is broken (see [`Invalid`]).
    #[error(transparent)]
    Invalid(#[from] Invalid),
    /// The GPU refused an operation: device creation, a resource beyond the
    /// adapter's limits, a failed readback.
    #[error("GPU: {0}")]
    Gpu(String),
}

/// A broken invariant of one of the crate's structures, as its `validate`
/// reports it. Every structure with invariants (`Mesh`, `Strips`,
/// `TriangleAdjacency`, `Collapses`, `MtsModel`, the baselines) has
/// `validate(&self) -> Result<(), Invalid>` (`TriangleAdjacency` takes its
/// mesh too); builders run it in debug builds, tests always.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("invalid {structure}: {message}")]
pub struct Invalid {
    /// The structure, e.g. `Collapses`.
    pub structure: &'static str,
    /// The first invariant found broken, and where.
    pub message: String,
}

/// Returns `Err(Invalid)` from the enclosing `validate` when `cond` fails:
/// `ensure!("Collapses", a < b, "step {i}: ...")`.
macro_rules! ensure {
    ($structure:expr, $cond:expr, $($message:tt)+) => {
        if !$cond {
            return Err($crate::error::Invalid {
                structure: $structure,
                message: format!($($message)+),
            });
        }
    };
}
pub(crate) use ensure;

/// `Result` with the crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
