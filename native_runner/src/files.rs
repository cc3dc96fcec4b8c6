//! Run folders on disk: a folder is built under a temporary sibling name and moved into place
//! whole, so a run folder is at every moment either the old or the new complete one. (Single
//! files go through `sfmeval_fs::write_atomic`.)

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

/// A unique temporary sibling name for `path` (`.NAME.partial-PID-N`).
pub fn partial_name(path: &Path) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static N: AtomicU64 = AtomicU64::new(0);
    let n = N.fetch_add(1, Ordering::Relaxed);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.partial-{}-{n}", std::process::id()))
}

/// Moves the finished folder `tmp` to `dest`, replacing an older `dest`: the old one is first
/// renamed aside, so `dest` is at every moment either the old or the new complete folder.
pub fn replace_dir(tmp: &Path, dest: &Path) -> Result<()> {
    if dest.exists() {
        let old = partial_name(dest);
        std::fs::rename(dest, &old).with_context(|| format!("moving {} aside", dest.display()))?;
        std::fs::rename(tmp, dest).with_context(|| format!("renaming to {}", dest.display()))?;
        std::fs::remove_dir_all(&old).with_context(|| format!("removing {}", old.display()))?;
    } else {
        std::fs::rename(tmp, dest).with_context(|| format!("renaming to {}", dest.display()))?;
    }
    Ok(())
}

/// Copies a folder tree.
pub fn copy_dir(src: &Path, dst: &Path) -> Result<()> {
    std::fs::create_dir_all(dst).with_context(|| format!("creating {}", dst.display()))?;
    for e in std::fs::read_dir(src).with_context(|| format!("reading {}", src.display()))? {
        let e = e?;
        let (from, to) = (e.path(), dst.join(e.file_name()));
        if e.file_type()?.is_dir() {
            copy_dir(&from, &to)?;
        } else {
            std::fs::copy(&from, &to)
                .with_context(|| format!("copying {} to {}", from.display(), to.display()))?;
        }
    }
    Ok(())
}
