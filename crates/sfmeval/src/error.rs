//! Typed errors of the core. Front ends add the file name and turn them into messages.

/// Everything that can go wrong in the core. Readers never panic on bad bytes: they return one
/// of these, and the kind says what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// The data ends before what its header or structure promises.
    #[error("{format} data is truncated: {detail}")]
    Truncated {
        /// Format being read ("PLY", "GLB", ...).
        format: &'static str,
        /// What was missing.
        detail: String,
    },
    /// The data does not follow its format.
    #[error("{format} data is malformed: {detail}")]
    Malformed {
        /// Format being read.
        format: &'static str,
        /// What is wrong and where.
        detail: String,
    },
    /// A declared count disagrees with the data present (also guards allocation bombs).
    #[error("{format} declares {declared} {what} but the data holds at most {available}")]
    CountMismatch {
        /// Format being read.
        format: &'static str,
        /// What is counted ("vertices", "faces", ...).
        what: &'static str,
        /// The count the header declares.
        declared: u64,
        /// The most the data can hold.
        available: u64,
    },
    /// Coordinates that are NaN or infinite.
    #[error(
        "{format} data has {count} non-finite coordinate(s); the first is {what} #{first_index}"
    )]
    NonFinite {
        /// Format being read.
        format: &'static str,
        /// What holds them ("vertex", "point", ...).
        what: &'static str,
        /// How many entries are affected.
        count: usize,
        /// Index of the first one.
        first_index: usize,
    },
    /// A valid file that uses a feature this reader cannot decode.
    #[error("{format}: {detail}")]
    Unsupported {
        /// Format being read.
        format: &'static str,
        /// The feature and what to do about it.
        detail: String,
    },
    /// Nothing to work with (no points, no triangles).
    #[error("{what} is empty")]
    Empty {
        /// What is empty.
        what: String,
    },
    /// The format of the input could not be recognised.
    #[error("unrecognised format: {0}")]
    UnknownFormat(String),
    /// An option value is out of its valid range or inconsistent.
    #[error("invalid option: {0}")]
    InvalidOption(String),
    /// Geometry that cannot be used (all triangles degenerate, zero-size scene, ...).
    #[error("unusable geometry: {0}")]
    Geometry(String),
    /// A file that could not be read at all (reported by a [`crate::files::FileSource`]).
    #[error("cannot read '{file}': {message}")]
    Io {
        /// The file's path as the source names it.
        file: String,
        /// What the system said.
        message: String,
    },
    /// A file an input needs is absent.
    #[error("missing {what} '{file}'")]
    Missing {
        /// What the file is for ("depth map for image 'a.jpg'", ...).
        what: String,
        /// The path looked for.
        file: String,
    },
    /// An error in one named input file: its role and path, then what is wrong in it.
    #[error("{role} '{file}': {cause}")]
    InFile {
        /// What the file is (`ground truth`, `reconstruction`, `ground-truth cameras`, ...).
        role: &'static str,
        /// The file's path as the front end named it.
        file: String,
        /// What is wrong.
        cause: Box<Error>,
    },
}

/// Shorthand result type of the core.
pub type Result<T, E = Error> = core::result::Result<T, E>;

impl Error {
    /// A short machine-readable name of the error kind (`"truncated"`, `"malformed"`, ...).
    pub fn kind(&self) -> &'static str {
        match self {
            Error::Truncated { .. } => "truncated",
            Error::Malformed { .. } => "malformed",
            Error::CountMismatch { .. } => "count_mismatch",
            Error::NonFinite { .. } => "non_finite",
            Error::Unsupported { .. } => "unsupported",
            Error::Empty { .. } => "empty",
            Error::UnknownFormat(_) => "unknown_format",
            Error::InvalidOption(_) => "invalid_option",
            Error::Geometry(_) => "geometry",
            Error::Io { .. } => "io",
            Error::Missing { .. } => "missing",
            Error::InFile { cause, .. } => cause.kind(),
        }
    }

    /// This error, as an error in the file `file` playing `role`.
    pub fn in_file(self, role: &'static str, file: impl Into<String>) -> Self {
        Error::InFile {
            role,
            file: file.into(),
            cause: Box::new(self),
        }
    }

    pub(crate) fn malformed(format: &'static str, detail: impl Into<String>) -> Self {
        Error::Malformed {
            format,
            detail: detail.into(),
        }
    }

    pub(crate) fn truncated(format: &'static str, detail: impl Into<String>) -> Self {
        Error::Truncated {
            format,
            detail: detail.into(),
        }
    }

    pub(crate) fn unsupported(format: &'static str, detail: impl Into<String>) -> Self {
        Error::Unsupported {
            format,
            detail: detail.into(),
        }
    }
}
