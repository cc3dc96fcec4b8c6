//! Dense clouds read from disk in pieces ([`sfmeval::io::ply_stream`]): the file's bytes never
//! sit in memory beside the decoded points.

use std::fs::File;
use std::io::Read as _;
use std::path::Path;

use anyhow::{Context as _, Result};
use sfmeval::io::ply::PlyData;
use sfmeval::io::ply_stream::{HEAD_BYTES, PlyCloudStream};
use sfmeval::model;
use sfmeval::pipeline::{self, ReconInput};

use crate::disk::{name_of, read_input_files};

/// Bytes read from the file at a time.
const PIECE_BYTES: usize = 8 << 20;

/// The binary PLY point cloud at `path`, read a piece at a time; `Ok(None)` when the file is
/// not one that streams (ascii, a mesh, ...: read it whole). Errors reading the file name it;
/// format errors are the core's, as from a whole-file read.
fn read_ply_cloud(path: &Path) -> Result<Option<PlyData>> {
    let what = || format!("cannot read '{}'", path.display());
    let mut file = File::open(path).with_context(what)?;
    let len = file.metadata().with_context(what)?.len();
    let mut head = Vec::with_capacity(HEAD_BYTES);
    (&mut file)
        .take(HEAD_BYTES as u64)
        .read_to_end(&mut head)
        .with_context(what)?;
    let Some(mut stream) = PlyCloudStream::new(&head, len)? else {
        return Ok(None);
    };
    if let Some(body) = head.get(stream.body_start()..) {
        stream.push(body);
    }
    let mut piece = vec![0u8; PIECE_BYTES];
    while !stream.is_complete() {
        let n = file.read(&mut piece).with_context(what)?;
        if n == 0 {
            break;
        }
        stream.push(&piece[..n]);
    }
    Ok(Some(stream.finish()?))
}

/// The reconstruction at `path` (a PLY cloud, a model folder or file), named `name` in the
/// report: a binary PLY cloud is read 8 MiB at a time through `sfmeval::io::ply_stream`,
/// anything else through [`read_input_files`] and [`pipeline::read_reconstruction`]; the same
/// [`ReconInput`] either way. Errors name the path.
pub fn read_reconstruction(path: &Path, name: &str) -> Result<ReconInput> {
    let context = || format!("reconstruction '{}'", path.display());
    if is_ply_file(path)
        && let Some(ply) = read_ply_cloud(path).with_context(context)?
    {
        let loaded = sfmeval::io::point_cloud_from_ply(&name_of(path), ply)
            .map_err(anyhow::Error::new)
            .with_context(context)?;
        return Ok(pipeline::reconstruction_from_cloud(name, loaded));
    }
    pipeline::read_reconstruction(name, &read_input_files(path)?).with_context(context)
}

/// [`read_reconstruction`], with the cameras of the model at `cameras_path` when given (a PLY
/// cloud evaluated with the cameras of the SfM model beside it, `--recon-cameras`).
pub fn read_reconstruction_with_cameras(
    path: &Path,
    cameras_path: Option<&Path>,
    name: &str,
) -> Result<ReconInput> {
    let Some(cameras_path) = cameras_path else {
        return read_reconstruction(path, name);
    };
    let files = read_input_files(path)?;
    let cameras = model::read_model_files(&read_input_files(cameras_path)?)
        .with_context(|| format!("reconstruction cameras '{}'", cameras_path.display()))?;
    pipeline::read_reconstruction_with_cameras(name, &files, cameras, &name_of(cameras_path))
        .with_context(|| format!("reconstruction '{}'", path.display()))
}

/// Whether `path` is a file named `*.ply` (any case).
fn is_ply_file(path: &Path) -> bool {
    path.is_file()
        && path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("ply"))
}
