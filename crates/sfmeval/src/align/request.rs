//! The alignment request every front end makes: a mode (the single list of mode names lives
//! here), the transform the user gave, and the point pairs. Parsed and validated once, so the
//! CLI's `--align/--transform/--pairs`, the wasm options and the runner's `--align` agree.

use std::fmt;

use crate::align::{AlignMethod, PointPair};
use crate::error::{AlignInputProblem, Error, Result};
use crate::transform::Similarity;

/// How the reconstruction is brought into the ground-truth frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AlignMode {
    /// `cameras` when both sides have cameras, else `points` with pairs, else `global`; then ICP.
    Auto,
    /// Camera centres (and orientations when the centres are nearly collinear), alone.
    Cameras,
    /// User point pairs, alone.
    Points,
    /// Shape-only multi-start search, alone.
    Global,
    /// Trimmed scaled ICP from the given transform (the identity when none).
    Icp,
    /// `cameras`, then ICP.
    CamerasIcp,
    /// `points`, then ICP.
    PointsIcp,
    /// `global`, then ICP.
    GlobalIcp,
    /// The given transform, as is.
    Given,
    /// No alignment: the reconstruction is already in the ground-truth frame.
    None,
}

impl AlignMode {
    /// Every mode, in the order front ends list them.
    pub const ALL: [AlignMode; 10] = [
        AlignMode::Auto,
        AlignMode::Cameras,
        AlignMode::Points,
        AlignMode::Global,
        AlignMode::Icp,
        AlignMode::CamerasIcp,
        AlignMode::PointsIcp,
        AlignMode::GlobalIcp,
        AlignMode::Given,
        AlignMode::None,
    ];

    /// The mode's name, as typed on a command line and written in reports.
    pub fn name(self) -> &'static str {
        match self {
            AlignMode::Auto => "auto",
            AlignMode::Cameras => "cameras",
            AlignMode::Points => "points",
            AlignMode::Global => "global",
            AlignMode::Icp => "icp",
            AlignMode::CamerasIcp => "cameras+icp",
            AlignMode::PointsIcp => "points+icp",
            AlignMode::GlobalIcp => "global+icp",
            AlignMode::Given => "given",
            AlignMode::None => "none",
        }
    }

    /// Every mode name, in [`Self::ALL`] order.
    pub fn names() -> [&'static str; 10] {
        Self::ALL.map(AlignMode::name)
    }

    /// Parses a mode name.
    pub fn parse(name: &str) -> Result<AlignMode> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| {
                Error::InvalidOption(format!(
                    "unknown alignment '{name}' (expected one of {})",
                    Self::names().join(", ")
                ))
            })
    }

    /// One line on what the mode does (help texts and the page's menu).
    pub fn description(self) -> &'static str {
        match self {
            AlignMode::Auto => "cameras, else point pairs, else global search; then ICP",
            AlignMode::Cameras => "camera centres (LO-RANSAC), no refinement",
            AlignMode::Points => "point pairs, no refinement",
            AlignMode::Global => "global shape search, no refinement",
            AlignMode::Icp => "ICP from the given transform (else the identity)",
            AlignMode::CamerasIcp => "camera centres, then ICP",
            AlignMode::PointsIcp => "point pairs, then ICP",
            AlignMode::GlobalIcp => "global shape search, then ICP",
            AlignMode::Given => "the given transform as is",
            AlignMode::None => "none: already in the ground-truth frame",
        }
    }

    /// Whether the mode cannot run without a transform.
    pub fn needs_transform(self) -> bool {
        self == AlignMode::Given
    }

    /// Whether the mode cannot run without point pairs.
    pub fn needs_pairs(self) -> bool {
        matches!(self, AlignMode::Points | AlignMode::PointsIcp)
    }

    /// Whether the mode cannot run without cameras on both sides.
    pub fn needs_cameras(self) -> bool {
        matches!(self, AlignMode::Cameras | AlignMode::CamerasIcp)
    }

    /// The alignment stages to run (`None` for `given` and `none`): the first stage and
    /// whether ICP refines it.
    pub(crate) fn stages(self) -> Option<(AlignMethod, bool)> {
        Some(match self {
            AlignMode::Auto => (AlignMethod::Auto, true),
            AlignMode::Cameras => (AlignMethod::Cameras, false),
            AlignMode::Points => (AlignMethod::Points, false),
            AlignMode::Global => (AlignMethod::Global, false),
            AlignMode::Icp => (AlignMethod::Icp, true),
            AlignMode::CamerasIcp => (AlignMethod::Cameras, true),
            AlignMode::PointsIcp => (AlignMethod::Points, true),
            AlignMode::GlobalIcp => (AlignMethod::Global, true),
            AlignMode::Given | AlignMode::None => return None,
        })
    }

    /// The mode that runs `method`, refined by ICP when `refine` (the inverse of
    /// [`Self::stages`]; `auto` and `icp` always end with ICP).
    pub(crate) fn of_stages(method: AlignMethod, refine: bool) -> AlignMode {
        match (method, refine) {
            (AlignMethod::Auto, _) => AlignMode::Auto,
            (AlignMethod::Icp, _) => AlignMode::Icp,
            (AlignMethod::Cameras, false) => AlignMode::Cameras,
            (AlignMethod::Points, false) => AlignMode::Points,
            (AlignMethod::Global, false) => AlignMode::Global,
            (AlignMethod::Cameras, true) => AlignMode::CamerasIcp,
            (AlignMethod::Points, true) => AlignMode::PointsIcp,
            (AlignMethod::Global, true) => AlignMode::GlobalIcp,
        }
    }
}

impl fmt::Display for AlignMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for AlignMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        AlignMode::parse(s)
    }
}

/// A validated alignment request.
#[derive(Debug, Clone, PartialEq)]
pub struct AlignRequest {
    /// The mode.
    pub mode: AlignMode,
    /// The user's `gt_from_recon`: used as is by `given`, as the start of `icp`.
    pub transform: Option<Similarity>,
    /// Point pairs for the `points` stages (also used by `auto` when there are no cameras).
    pub pairs: Vec<PointPair>,
}

impl Default for AlignRequest {
    fn default() -> Self {
        AlignRequest {
            mode: AlignMode::Auto,
            transform: None,
            pairs: Vec::new(),
        }
    }
}

impl AlignRequest {
    /// Builds and validates a request. Without a mode: `given` when a transform is given, else
    /// `auto`. Errors: `none` with a transform (it would be ignored), `given` without one,
    /// `points`/`points+icp` without pairs, a transform with a mode that does not use it.
    pub fn new(
        mode: Option<AlignMode>,
        transform: Option<Similarity>,
        pairs: Vec<PointPair>,
    ) -> Result<AlignRequest> {
        let mode = mode.unwrap_or(if transform.is_some() {
            AlignMode::Given
        } else {
            AlignMode::Auto
        });
        let request = AlignRequest {
            mode,
            transform,
            pairs,
        };
        request.validate()?;
        Ok(request)
    }

    /// A request with no alignment.
    pub fn none() -> AlignRequest {
        AlignRequest {
            mode: AlignMode::None,
            ..AlignRequest::default()
        }
    }

    /// A request that runs `mode`'s stages without a transform or pairs.
    #[cfg(test)]
    pub(crate) fn mode(mode: AlignMode) -> AlignRequest {
        AlignRequest {
            mode,
            ..AlignRequest::default()
        }
    }

    /// Checks that the mode has what it needs and that nothing given is ignored
    /// ([`Error::AlignInput`]).
    pub fn validate(&self) -> Result<()> {
        let mode = self.mode;
        let problem = if mode.needs_transform() && self.transform.is_none() {
            AlignInputProblem::MissingTransform
        } else if mode.needs_pairs() && self.pairs.is_empty() {
            AlignInputProblem::MissingPairs
        } else if self.transform.is_some() && !matches!(mode, AlignMode::Given | AlignMode::Icp) {
            if mode == AlignMode::None {
                AlignInputProblem::TransformIgnoredUseGiven
            } else {
                AlignInputProblem::TransformIgnored
            }
        } else {
            return Ok(());
        };
        Err(Error::AlignInput {
            mode: mode.name(),
            problem,
        })
    }
}

impl fmt::Display for AlignRequest {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.mode.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_are_unique() {
        for m in AlignMode::ALL {
            assert_eq!(AlignMode::parse(m.name()).unwrap(), m);
            assert_eq!(m.to_string(), m.name());
        }
        let mut names = AlignMode::names().to_vec();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), AlignMode::ALL.len());
        let e = AlignMode::parse("icp+cameras").unwrap_err().to_string();
        assert!(e.contains("cameras+icp"), "{e}");
    }

    #[test]
    fn default_mode_depends_on_the_transform() {
        let t = Similarity::IDENTITY;
        assert_eq!(
            AlignRequest::new(None, Some(t), vec![]).unwrap().mode,
            AlignMode::Given
        );
        assert_eq!(
            AlignRequest::new(None, None, vec![]).unwrap().mode,
            AlignMode::Auto
        );
    }

    #[test]
    fn missing_or_ignored_inputs_are_errors() {
        let t = Some(Similarity::IDENTITY);
        let pair = PointPair {
            recon: [0.0; 3],
            gt: [0.0; 3],
        };
        let err = |m, t, p| AlignRequest::new(Some(m), t, p).unwrap_err().to_string();
        assert!(err(AlignMode::Given, None, vec![]).contains("needs a transform"));
        assert!(err(AlignMode::Points, None, vec![]).contains("needs point pairs"));
        assert!(err(AlignMode::PointsIcp, None, vec![]).contains("needs point pairs"));
        assert!(err(AlignMode::None, t, vec![]).contains("use 'given'"));
        assert!(err(AlignMode::Cameras, t, vec![]).contains("ignores the transform"));
        assert!(AlignRequest::new(Some(AlignMode::Icp), t, vec![]).is_ok());
        // Typed, so that front ends name their own flag.
        assert_eq!(
            AlignRequest::new(Some(AlignMode::PointsIcp), None, vec![]),
            Err(Error::AlignInput {
                mode: "points+icp",
                problem: AlignInputProblem::MissingPairs
            })
        );
        assert!(AlignRequest::new(Some(AlignMode::Points), None, vec![pair]).is_ok());
    }

    #[test]
    fn stages_say_what_runs_and_what_refines() {
        assert_eq!(
            AlignMode::CamerasIcp.stages(),
            Some((AlignMethod::Cameras, true))
        );
        assert_eq!(
            AlignMode::Points.stages(),
            Some((AlignMethod::Points, false))
        );
        assert_eq!(AlignMode::Auto.stages(), Some((AlignMethod::Auto, true)));
        assert_eq!(AlignMode::Given.stages(), None);
        for mode in AlignMode::ALL {
            if let Some((method, refine)) = mode.stages() {
                assert_eq!(AlignMode::of_stages(method, refine), mode);
            }
        }
        assert!(AlignMode::CamerasIcp.needs_cameras() && !AlignMode::Auto.needs_cameras());
    }
}
