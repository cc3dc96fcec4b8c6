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
    /// What a file or a field holds is wrong (a transform that is no similarity, a crop file
    /// that does not parse, a trajectory with the wrong number of frames): the message names
    /// the content and says what is wrong; front ends add the file ([`Error::in_file`]).
    #[error("{0}")]
    InvalidContent(String),
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
    /// A finite value that makes no sense or lies beyond what the core can measure: a zero or
    /// huge image width, a negative focal length, a rotation that is not one, a coordinate
    /// beyond ±1e50. Names the item (`camera 3`, `image 'a.jpg'`,
    /// `vertex #12`) and the field; front ends add the file name.
    #[error("{format}: {item}: {field} {problem}")]
    OutOfRange {
        /// Format being read ("COLMAP text", "cameras.json", ...).
        format: &'static str,
        /// What holds the value: `camera 3`, `image 'a.jpg'`, `vertex #12`, `node 4`.
        item: String,
        /// The field: `width`, `focal length fx`, `rotation`, `x`.
        field: String,
        /// What is wrong, with the value and the accepted range.
        problem: String,
    },
    /// A well-formed input whose expanded size passes a limit of [`crate::io::ReadLimits`]
    /// (a glTF scene instancing meshes into more triangles than allowed), refused before
    /// anything is allocated for it.
    #[error("{format}: {what}: {count} is above the limit of {limit}{hint}")]
    LimitExceeded {
        /// Format being read.
        format: &'static str,
        /// What is counted (`triangles once every node instance is expanded`).
        what: String,
        /// The count the input would need.
        count: u64,
        /// The limit in force.
        limit: u64,
        /// How to raise the limit, with a leading separator (may be empty).
        hint: &'static str,
    },
    /// The user's point pairs (the `points` alignment's pairs file) cannot be used: too few,
    /// collinear, non-finite, out of range. A distinct variant so that front ends name the pairs
    /// file rather than the reconstruction ([`Error::concerns_point_pairs`]).
    #[error("point pairs: {0}")]
    PointPairs(String),
    /// An alignment request whose mode lacks an input it needs or is given one it would
    /// ignore. Typed so that front ends can name their own flag or field for the input.
    #[error("alignment '{mode}' {problem}")]
    AlignInput {
        /// The mode's name (`given`, `points+icp`, ...).
        mode: &'static str,
        /// What is missing or ignored.
        problem: AlignInputProblem,
    },
}

/// What is wrong with an alignment request's inputs ([`Error::AlignInput`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum AlignInputProblem {
    /// `given` without a transform.
    #[error("needs a transform")]
    MissingTransform,
    /// `points` or `points+icp` without point pairs.
    #[error("needs point pairs")]
    MissingPairs,
    /// `none`: a transform it would ignore (`given` uses it, the default with a transform).
    #[error("ignores the transform (use 'given', the default with a transform)")]
    TransformIgnoredUseGiven,
    /// A mode other than `given`, `icp` or `none` with a transform it would ignore.
    #[error("ignores the transform (it is used by 'given' and as the start of 'icp')")]
    TransformIgnored,
}

/// The format name of point-pairs files in errors (`crate::align::points::PAIRS_FORMAT`): the
/// errors that carry it concern the pairs file ([`Error::concerns_point_pairs`]).
pub(crate) const POINT_PAIRS_FORMAT: &str = "point pairs";

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
            Error::InvalidContent(_) => "invalid_content",
            Error::Geometry(_) => "geometry",
            Error::Io { .. } => "io",
            Error::Missing { .. } => "missing",
            Error::InFile { cause, .. } => cause.kind(),
            Error::OutOfRange { .. } => "out_of_range",
            Error::LimitExceeded { .. } => "limit_exceeded",
            Error::PointPairs(_) => "point_pairs",
            Error::AlignInput { .. } => "align_input",
        }
    }

    /// True when the error is about the point pairs (the pairs file of the `points` alignment),
    /// whether found while parsing it ([`crate::align::parse_point_pairs`]) or while aligning
    /// with it ([`crate::align::align_points`]): front ends then name the pairs file, not the
    /// reconstruction.
    pub fn concerns_point_pairs(&self) -> bool {
        match self {
            Error::PointPairs(_) => true,
            Error::InFile { cause, .. } => cause.concerns_point_pairs(),
            Error::Malformed { format, .. }
            | Error::Truncated { format, .. }
            | Error::NonFinite { format, .. }
            | Error::OutOfRange { format, .. } => *format == POINT_PAIRS_FORMAT,
            _ => false,
        }
    }

    /// An [`Error::OutOfRange`].
    pub(crate) fn out_of_range(
        format: &'static str,
        item: impl Into<String>,
        field: impl Into<String>,
        problem: impl Into<String>,
    ) -> Self {
        Error::OutOfRange {
            format,
            item: item.into(),
            field: field.into(),
            problem: problem.into(),
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
