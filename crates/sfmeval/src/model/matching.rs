//! Pairs a reconstruction's images with ground-truth images by file name, ignoring folders
//! (`/` and `\`) and the case of the extension: `images/0001.JPG` ↔ `0001.jpg`. When a name
//! has no exact key match, its stem alone is tried (a tool that converted `0001.png` to
//! `0001.jpg`), if that stem is unique on both sides.

use crate::note::{Code, Note};
use std::collections::BTreeMap;

use super::Reconstruction;
#[cfg(test)]
use crate::geometry::Point3;

/// The matching key of an image name: the file name without folders, extension lower-cased.
pub(crate) fn image_key(name: &str) -> String {
    let base = name.rsplit(['/', '\\']).next().unwrap_or(name).trim();
    match base.rsplit_once('.') {
        Some((stem, ext)) if !stem.is_empty() => format!("{stem}.{}", ext.to_ascii_lowercase()),
        _ => base.to_string(),
    }
}

fn stem_key(name: &str) -> String {
    let key = image_key(name);
    match key.rsplit_once('.') {
        Some((stem, _)) if !stem.is_empty() => stem.to_string(),
        _ => key,
    }
}

/// The result of [`match_images`].
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct ImageMatches {
    /// `(ground-truth image index, estimated image index)` pairs, in ground-truth order.
    pub pairs: Vec<(usize, usize)>,
    /// Ground-truth images without an estimate (unregistered or absent).
    pub unmatched_gt: Vec<usize>,
    /// Estimated images whose name is in no ground-truth image.
    pub unmatched_est: Vec<usize>,
    /// Problems: duplicate keys, stem-only matches.
    pub notes: Vec<Note>,
}

/// Matches the images of `est` to those of `gt` by [`image_key`] (then by unique stem).
/// Duplicate keys on one side keep their first image and are reported.
pub(crate) fn match_images(gt: &Reconstruction, est: &Reconstruction) -> ImageMatches {
    let gt_names: Vec<&str> = gt.images.iter().map(|i| i.name.as_str()).collect();
    let est_names: Vec<&str> = est.images.iter().map(|i| i.name.as_str()).collect();
    match_names(&gt_names, &est_names)
}

/// [`match_images`] on plain name lists.
pub(crate) fn match_names(gt: &[&str], est: &[&str]) -> ImageMatches {
    let mut out = ImageMatches::default();
    let index = |names: &[&str], key: fn(&str) -> String, side: &str, warn: &mut Vec<Note>| {
        let mut map: BTreeMap<String, usize> = BTreeMap::new();
        let mut dups = Vec::new();
        for (i, n) in names.iter().enumerate() {
            let k = key(n);
            match map.entry(k) {
                std::collections::btree_map::Entry::Occupied(o) => dups.push(o.key().clone()),
                std::collections::btree_map::Entry::Vacant(v) => {
                    v.insert(i);
                }
            }
        }
        if !dups.is_empty() {
            warn.push(
                Note::new(
                    Code::DuplicateImageNames,
                    format!(
                        "{} {side} image name(s) are not unique once folders are ignored (first kept): {}",
                        dups.len(),
                        dups.iter().take(5).cloned().collect::<Vec<_>>().join(", ")
                    ),
                )
                .with("side", side)
                .with("count", dups.len()),
            );
        }
        map
    };
    let mut warnings = Vec::new();
    let gt_map = index(gt, image_key, "ground-truth", &mut warnings);
    let mut matched_gt: Vec<Option<usize>> = vec![None; gt.len()];
    let mut used_est = vec![false; est.len()];
    let mut est_dups = 0usize;
    for (e, n) in est.iter().enumerate() {
        if let Some(&g) = gt_map.get(&image_key(n)) {
            match matched_gt.get_mut(g) {
                Some(slot @ None) => {
                    *slot = Some(e);
                    if let Some(u) = used_est.get_mut(e) {
                        *u = true;
                    }
                }
                _ => est_dups += 1,
            }
        }
    }
    if est_dups > 0 {
        warnings.push(
            Note::new(
                Code::DuplicateImageNames,
                format!(
                    "{est_dups} estimated image(s) repeat the name of another estimated image; first kept"
                ),
            )
            .with("side", "estimated")
            .with("count", est_dups),
        );
    }
    // Stem fallback for what is left, unique stems only.
    let stems = |names: &[&str], free: &dyn Fn(usize) -> bool| {
        let mut map: BTreeMap<String, Option<usize>> = BTreeMap::new();
        for (i, n) in names.iter().enumerate().filter(|(i, _)| free(*i)) {
            map.entry(stem_key(n))
                .and_modify(|v| *v = None)
                .or_insert(Some(i));
        }
        map
    };
    let gt_free = stems(gt, &|i| matched_gt.get(i).is_some_and(Option::is_none));
    let est_free = stems(est, &|i| used_est.get(i).is_some_and(|u| !u));
    let mut stem_matches = 0usize;
    for (stem, g) in &gt_free {
        if let (Some(g), Some(Some(e))) = (g, est_free.get(stem)) {
            if let Some(slot) = matched_gt.get_mut(*g) {
                *slot = Some(*e);
            }
            if let Some(u) = used_est.get_mut(*e) {
                *u = true;
            }
            stem_matches += 1;
        }
    }
    if stem_matches > 0 {
        warnings.push(
            Note::new(
                Code::ImagesMatchedByStem,
                format!(
                    "{stem_matches} image(s) matched by file stem only (the extension differs)"
                ),
            )
            .with("count", stem_matches),
        );
    }
    for (g, m) in matched_gt.iter().enumerate() {
        match m {
            Some(e) => out.pairs.push((g, *e)),
            None => out.unmatched_gt.push(g),
        }
    }
    out.unmatched_est = used_est
        .iter()
        .enumerate()
        .filter(|(_, u)| !**u)
        .map(|(i, _)| i)
        .collect();
    out.notes = warnings;
    out
}

/// The camera centres of matched images, `(ground truth, estimate)`, in match order: the input
/// of a camera-based alignment.
#[cfg(test)]
pub(crate) fn matched_centers(
    gt: &Reconstruction,
    est: &Reconstruction,
    matches: &ImageMatches,
) -> (Vec<Point3>, Vec<Point3>) {
    matches
        .pairs
        .iter()
        .filter_map(|&(g, e)| Some((gt.images.get(g)?.center(), est.images.get(e)?.center())))
        .unzip()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_ignore_folders_and_extension_case() {
        assert_eq!(image_key("images/0001.JPG"), "0001.jpg");
        assert_eq!(image_key("C:\\data\\img\\0001.Jpg"), "0001.jpg");
        assert_eq!(image_key("0001.jpg"), "0001.jpg");
        assert_eq!(image_key("IMG_01.JPG"), "IMG_01.jpg");
        assert_ne!(image_key("img_01.jpg"), image_key("IMG_01.jpg"));
        assert_eq!(image_key(".hidden"), ".hidden");
        assert_eq!(image_key("noext"), "noext");
    }

    #[test]
    fn matching_with_folders_duplicates_and_stems() {
        let gt = ["0000.jpg", "0001.jpg", "0002.jpg", "0003.png"];
        let est = [
            "x/0001.JPG",
            "0000.jpg",
            "y/0001.jpg",
            "other.jpg",
            "0003.jpg",
        ];
        let m = match_names(&gt, &est);
        assert_eq!(m.pairs, vec![(0, 1), (1, 0), (3, 4)]);
        assert_eq!(m.unmatched_gt, vec![2]);
        assert_eq!(m.unmatched_est, vec![2, 3]);
        assert!(m.notes.iter().any(|w| w.message.contains("repeat")));
        assert!(m.notes.iter().any(|w| w.code == Code::ImagesMatchedByStem));
        let none = match_names(&gt, &["a.jpg"]);
        assert!(none.pairs.is_empty());
        assert_eq!(none.unmatched_gt.len(), 4);
    }
}
