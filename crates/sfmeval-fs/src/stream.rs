//! Dense clouds read from disk in pieces ([`sfmeval::io::ply_stream`]): the file's bytes never
//! sit in memory beside the decoded points.

use std::fs::File;
use std::io::Read as _;
use std::path::Path;

use anyhow::{Context as _, Result};
use sfmeval::io::LoadedCloud;
use sfmeval::io::ply::PlyData;
use sfmeval::io::ply_stream::{HEAD_BYTES, PlyCloudStream};
use sfmeval::model;
use sfmeval::parallel;
use sfmeval::pipeline::{self, ReconInput};

use crate::disk::{name_of, read_input_files};

/// Bytes read from the file at a time.
const PIECE_BYTES: usize = 8 << 20;

/// The binary PLY point cloud at `path`, read a piece at a time; `Ok(None)` when the file is
/// not one that streams (ascii, a mesh, ...: read it whole). The next piece is read while the
/// last one is decoded. Errors reading the file are [`sfmeval::Error::Io`] naming it; format
/// errors are the core's, as from a whole-file read.
fn read_ply_cloud(path: &Path) -> sfmeval::Result<Option<PlyData>> {
    read_ply_cloud_in_pieces(path, PIECE_BYTES)
}

/// The point cloud in the binary PLY file at `path`, read in pieces ([`read_ply_cloud`]) and
/// named `name` in the core's errors; `Ok(None)` when `path` is not a `.ply` file that streams
/// (read it whole).
pub(crate) fn read_streamed_cloud(path: &Path, name: &str) -> sfmeval::Result<Option<LoadedCloud>> {
    if !is_ply_file(path) {
        return Ok(None);
    }
    read_ply_cloud(path)?
        .map(|ply| sfmeval::io::point_cloud_from_ply(name, ply))
        .transpose()
}

/// [`read_ply_cloud`] with pieces of `piece_bytes`.
fn read_ply_cloud_in_pieces(path: &Path, piece_bytes: usize) -> sfmeval::Result<Option<PlyData>> {
    let io = |e: std::io::Error| sfmeval::Error::Io {
        file: path.display().to_string(),
        message: e.to_string(),
    };
    let mut file = File::open(path).map_err(io)?;
    let len = file.metadata().map_err(io)?.len();
    let mut head = Vec::with_capacity(HEAD_BYTES);
    (&mut file)
        .take(HEAD_BYTES as u64)
        .read_to_end(&mut head)
        .map_err(io)?;
    let Some(mut stream) = PlyCloudStream::new(&head, len)? else {
        return Ok(None);
    };
    if let Some(body) = head.get(stream.body_start()..) {
        stream.push(body);
    }
    drop(head);
    let (mut piece, mut next) = (vec![0u8; piece_bytes], vec![0u8; piece_bytes]);
    let mut filled = fill(&mut file, &mut piece).map_err(io)?;
    while filled > 0 && !stream.is_complete() {
        let (read, ()) = parallel::join(
            || fill(&mut file, &mut next),
            || stream.push(&piece[..filled]),
        );
        filled = read.map_err(io)?;
        std::mem::swap(&mut piece, &mut next);
    }
    Ok(Some(stream.finish()?))
}

/// Reads from `file` until `buf` is full or the file ends; the bytes read.
fn fill(file: &mut File, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match file.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

/// The reconstruction at `path` (a PLY cloud, a model folder or file), named `name` in the
/// report: a binary PLY cloud is read 8 MiB at a time through `sfmeval::io::ply_stream`,
/// anything else through [`read_input_files`] and [`pipeline::read_reconstruction`]; the same
/// [`ReconInput`] either way. Errors name the path.
pub fn read_reconstruction(path: &Path, name: &str) -> Result<ReconInput> {
    let context = || format!("reconstruction '{}'", path.display());
    if let Some(loaded) = read_streamed_cloud(path, &name_of(path)).with_context(context)? {
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
pub(crate) fn is_ply_file(path: &Path) -> bool {
    path.is_file()
        && path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("ply"))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// A binary PLY of `n` points (`double` x, y, z and `uchar` colours: 27-byte records, so
    /// that pieces of most sizes split records).
    fn ply_bytes(n: usize) -> Vec<u8> {
        let mut out = format!(
            "ply\nformat binary_little_endian 1.0\nelement vertex {n}\nproperty double x\nproperty double y\nproperty double z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n"
        )
        .into_bytes();
        for i in 0..n {
            let f = i as f64;
            for v in [f * 0.5, -f, f * f * 1e-3] {
                out.extend_from_slice(&v.to_le_bytes());
            }
            out.extend([(i % 256) as u8, (i / 256 % 256) as u8, 7]);
        }
        out
    }

    #[test]
    fn pieces_of_any_size_read_as_the_whole_file() {
        let dir = std::env::temp_dir().join(format!("sfmeval-fs-stream-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("cloud.ply");
        let bytes = ply_bytes(5_000);
        std::fs::write(&path, &bytes).unwrap();
        let whole = sfmeval::io::ply::read_ply(&bytes).unwrap();
        for piece in [1, 26, 27, 1000, 4096, bytes.len(), 1 << 20] {
            let read = read_ply_cloud_in_pieces(&path, piece).unwrap().unwrap();
            assert_eq!(read.vertices, whole.vertices, "pieces of {piece} bytes");
            assert_eq!(read.colors, whole.colors, "pieces of {piece} bytes");
        }
        // A file cut inside its body: the whole-file reader's error.
        std::fs::write(&path, &bytes[..bytes.len() - 40]).unwrap();
        let cut = read_ply_cloud_in_pieces(&path, 1000)
            .unwrap_err()
            .to_string();
        let whole_cut = sfmeval::io::ply::read_ply(&bytes[..bytes.len() - 40])
            .unwrap_err()
            .to_string();
        assert_eq!(cut, whole_cut);
        // An ascii PLY does not stream.
        std::fs::write(
            &path,
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n",
        )
        .unwrap();
        assert!(read_ply_cloud_in_pieces(&path, 1000).unwrap().is_none());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
