//! Typed notes: everything a report tells its reader besides the numbers. A note has a stable
//! `code` (listed in [`Code::ALL`], `schemas/report.schema.json` and `docs/notes.md`), a
//! `level` fixed by its code, the message in words for people, and the values the message
//! states (counts, shares, thresholds), so that front ends pick, place and style notes by code
//! and never read the message text.

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use serde_json::{Map, Value};

/// How much a note matters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub enum Level {
    /// Routine information on how the numbers were made.
    Info,
    /// A number may be doubtful, or something was left out.
    Warning,
}

impl Level {
    /// `info` or `warning`.
    pub fn as_str(self) -> &'static str {
        match self {
            Level::Info => "info",
            Level::Warning => "warning",
        }
    }
}

/// Declares the code catalogue: variant, code text, level, what it means.
macro_rules! codes {
    ($($(#[doc = $doc:literal])+ $variant:ident = $code:literal, $level:ident;)+) => {
        /// The stable code of a note (serialized as its text, e.g. `alignment.icp_rejected`).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
        // TypeScript: the union of the code texts (each variant renamed to its text)
        #[cfg_attr(feature = "ts", derive(ts_rs::TS))]
        pub enum Code {
            $($(#[doc = $doc])+ #[cfg_attr(feature = "ts", ts(rename = $code))] $variant,)+
        }

        impl Code {
            /// Every code, in catalogue order.
            pub const ALL: &'static [Code] = &[$(Code::$variant,)+];

            /// The code's text.
            pub fn as_str(self) -> &'static str {
                match self {
                    $(Code::$variant => $code,)+
                }
            }

            /// The level every note of this code has.
            pub fn level(self) -> Level {
                match self {
                    $(Code::$variant => Level::$level,)+
                }
            }

            /// What the code means (its catalogue entry).
            pub fn meaning(self) -> &'static str {
                match self {
                    $(Code::$variant => concat!($($doc),+).trim_ascii(),)+
                }
            }
        }
    };
}

codes! {
    // ---- inputs ------------------------------------------------------------------------
    /// The SfM model has cameras but no 3D points.
    ModelNoPoints = "input.model_no_points", Warning;
    /// The model holds several separate reconstructions; the largest was used.
    SeveralModels = "input.several_models", Warning;
    /// Incomplete model files (a part missing) were found and ignored.
    IncompleteModelIgnored = "input.incomplete_model_ignored", Warning;
    /// Several model files were found beside each other; one was read.
    SeveralModelFiles = "input.several_model_files", Warning;
    /// A model file had unreadable lines at its end; reading stopped there.
    TrailingContent = "input.trailing_content", Warning;
    /// Observations or track elements refer to cameras, images or points not in the model; dropped.
    DanglingReferences = "input.dangling_references", Warning;
    /// A Bundler model without its image list: images are named by their index.
    NoImageList = "input.no_image_list", Warning;
    /// Images of the model have no pose (unregistered).
    UnregisteredImages = "input.unregistered_images", Info;
    /// Posed views have no valid intrinsics; counted as unregistered.
    MissingIntrinsics = "input.missing_intrinsics", Warning;
    /// The format stores no principal point or image size.
    NoPrincipalPoint = "input.no_principal_point", Info;
    /// Cameras with width and height 0 (unknown size).
    UnknownImageSize = "input.unknown_image_size", Info;
    /// Cameras whose principal point lies outside the image.
    PrincipalPointOutside = "input.principal_point_outside", Warning;
    /// A `cameras.json` names a frame other than `gltf` or `reconstruction`.
    UnknownCameraFrame = "input.unknown_camera_frame", Warning;
    /// Points the SfM tool wrote at its camera centres were removed from the cloud.
    CameraCentresRemoved = "input.camera_centres_removed", Info;
    /// A point cloud is evaluated with the cameras of a model beside it.
    CloudWithModelCameras = "input.cloud_with_model_cameras", Info;
    /// No point of the cloud lies at a camera centre of the model beside it.
    NoPointAtCameraCentres = "input.no_point_at_camera_centres", Info;
    /// The reconstruction is a mesh; only its vertices are evaluated.
    MeshVerticesOnly = "input.mesh_vertices_only", Info;
    /// Faces with fewer than 3 vertices were skipped.
    DegenerateFacesSkipped = "input.degenerate_faces_skipped", Warning;
    /// A glTF primitive that is not a surface (points, lines) was skipped.
    NonSurfacePrimitiveSkipped = "input.non_surface_primitive_skipped", Info;
    /// Estimated images repeat the name of another; the first was kept.
    DuplicateImageNames = "input.duplicate_image_names", Warning;
    /// Images matched the ground truth's by file stem only (the extension differs).
    ImagesMatchedByStem = "input.images_matched_by_stem", Info;
    // ---- cameras ------------------------------------------------------------------------
    /// Ground-truth cameras were given but the reconstruction is a bare cloud.
    ReconstructionHasNoCameras = "cameras.reconstruction_has_no_cameras", Warning;
    /// No estimated image name matches a ground-truth one: no camera alignment, no pose errors.
    NoImageInCommon = "cameras.no_image_in_common", Warning;
    /// Estimated poses are NaN or infinite; counted as unregistered.
    NonFinitePoses = "cameras.non_finite_poses", Warning;
    /// Fewer than 3 cameras matched: pose statistics are not meaningful.
    FewMatchedCameras = "cameras.few_matched", Warning;
    /// Estimated images without a ground-truth image of the same name.
    UnmatchedEstimatedImages = "cameras.unmatched_estimated", Warning;
    /// The scene radius is 0 or tiny: centre errors in percent are not given.
    SceneRadiusDegenerate = "cameras.scene_radius_degenerate", Warning;
    /// Estimated camera centres leave the f64 range once aligned; counted as unregistered.
    CentresOutOfRange = "cameras.centres_out_of_range", Warning;
    /// Relative pose errors use every k-th image pair (too many pairs).
    RelativePairsSubsampled = "cameras.relative_pairs_subsampled", Info;
    /// The pose errors were measured after the final transform: the cameras could not be aligned.
    PosesAfterFinalTransform = "cameras.poses_after_final_transform", Warning;
    // ---- alignment ----------------------------------------------------------------------
    /// Non-finite reconstruction points were ignored by an alignment stage.
    NonFinitePointsIgnored = "alignment.non_finite_points_ignored", Warning;
    /// The global shape search: how many starts it tried and the best one's score.
    GlobalSearchResult = "alignment.global_search_result", Info;
    /// Another pose far from the chosen one fits almost as well: the object may be symmetric.
    AmbiguousPose = "alignment.ambiguous_pose", Warning;
    /// The ICP refinement was rejected; the previous stage's transform is used.
    IcpRejected = "alignment.icp_rejected", Warning;
    /// An alignment stage of `auto` failed; the next possibility was used.
    StageFailed = "alignment.stage_failed", Warning;
    /// `auto` fell back to another stage.
    FellBack = "alignment.fell_back", Warning;
    /// ICP started from the identity (no start transform given).
    IcpFromIdentity = "alignment.icp_from_identity", Warning;
    /// Cameras left out of the camera alignment as outliers.
    CameraOutliers = "alignment.camera_outliers", Warning;
    /// Camera pairs with non-finite poses were skipped by the camera alignment.
    NonFiniteCameraPairs = "alignment.non_finite_camera_pairs", Warning;
    /// Camera centres too few or collinear: rotation from the orientations.
    CameraCentresDegenerate = "alignment.camera_centres_degenerate", Info;
    /// The final stage fitted few of the points inside its distance gate.
    FewInliers = "alignment.few_inliers", Warning;
    /// The final stage stopped before settling, but its fit is tight.
    UnsettledTightFit = "alignment.unsettled_tight_fit", Info;
    /// The final stage stopped before settling and its fit is loose.
    UnsettledLooseFit = "alignment.unsettled_loose_fit", Warning;
    // ---- measurement --------------------------------------------------------------------
    /// Signed distances need a mesh ground truth; reported unsigned only.
    SignedNeedsMesh = "measure.signed_needs_mesh", Info;
    /// The crop discarded every reconstructed point.
    CropDiscardedEverything = "measure.crop_discarded_everything", Warning;
    /// No ground-truth sample lies inside the crop volume.
    NoGroundTruthInCrop = "measure.no_ground_truth_in_crop", Warning;
    /// No completeness sample is seen by the required number of ground-truth images.
    NothingVisible = "measure.nothing_visible", Warning;
    /// The track-based error was not computed (see the message for why).
    NoTrackError = "measure.no_track_error", Info;
    /// No point could be measured by its track.
    NoTrackMeasured = "measure.no_track_measured", Warning;
    // ---- Tanks and Temples --------------------------------------------------------------
    /// The trajectory alignment brought fewer than half the cameras near the reference.
    TrajectoryPoorlyAligned = "tanksandtemples.trajectory_poorly_aligned", Warning;
    /// No reconstructed point lies inside the scene's crop: precision, recall and F are 0.
    NothingInSceneCrop = "tanksandtemples.nothing_in_crop", Warning;
}

impl Serialize for Code {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
    }
}

impl<'de> Deserialize<'de> for Code {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        Code::ALL
            .iter()
            .copied()
            .find(|c| c.as_str() == text)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown note code '{text}'")))
    }
}

/// One note of a report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct Note {
    /// Stable code.
    pub code: Code,
    /// `info` or `warning` (the code's level).
    pub level: Level,
    /// What happened, in words for people.
    pub message: String,
    /// The values the message states, by name (counts, shares, thresholds, the stage).
    #[serde(default, skip_serializing_if = "Map::is_empty")]
    pub values: Map<String, Value>,
}

impl Note {
    /// A note of `code` with its message and no values yet.
    pub fn new(code: Code, message: impl Into<String>) -> Note {
        Note {
            code,
            level: code.level(),
            message: message.into(),
            values: Map::new(),
        }
    }

    /// Adds a value (a count, share, threshold or name the message states).
    pub fn with(mut self, name: &str, value: impl Into<Value>) -> Note {
        self.values.insert(name.to_string(), value.into());
        self
    }

    /// Adds a number; a non-finite one is kept as its text (JSON has no NaN).
    pub fn with_number(self, name: &str, value: f64) -> Note {
        match serde_json::Number::from_f64(value) {
            Some(n) => self.with(name, Value::Number(n)),
            None => self.with(name, value.to_string()),
        }
    }

    /// The same note with `prefix` before its message (e.g. `ground-truth cameras: `).
    pub(crate) fn prefixed(mut self, prefix: &str) -> Note {
        self.message = format!("{prefix}{}", self.message);
        self
    }
}

impl std::fmt::Display for Note {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_are_unique_dotted_and_round_trip() {
        let mut seen = std::collections::BTreeSet::new();
        for &c in Code::ALL {
            let text = c.as_str();
            assert!(seen.insert(text), "duplicate code {text}");
            let (group, name) = text.split_once('.').expect("group.name");
            assert!(
                [
                    "input",
                    "cameras",
                    "alignment",
                    "measure",
                    "tanksandtemples"
                ]
                .contains(&group),
                "code {text} is in no known group"
            );
            assert!(name.bytes().all(|b| b.is_ascii_lowercase() || b == b'_'));
            assert!(!c.meaning().is_empty());
            let json = serde_json::to_string(&c).unwrap();
            assert_eq!(serde_json::from_str::<Code>(&json).unwrap(), c);
        }
        assert!(serde_json::from_str::<Code>("\"input.nope\"").is_err());
    }

    #[test]
    fn a_note_serializes_code_level_message_values() {
        let n = Note::new(Code::IcpRejected, "rejected")
            .with("stage", "icp")
            .with_number("inlier_ratio", 0.25)
            .with_number("bad", f64::NAN);
        let json = serde_json::to_string(&n).unwrap();
        assert_eq!(
            json,
            r#"{"code":"alignment.icp_rejected","level":"warning","message":"rejected","values":{"bad":"NaN","inlier_ratio":0.25,"stage":"icp"}}"#
        );
        assert_eq!(serde_json::from_str::<Note>(&json).unwrap(), n);
        let bare = serde_json::to_string(&Note::new(Code::SignedNeedsMesh, "m")).unwrap();
        assert!(!bare.contains("values"));
    }
}
