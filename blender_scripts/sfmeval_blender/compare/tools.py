"""Where the ``sfmeval`` and ``sfmeval-runner`` binaries are: the path set in the add-on's
preferences, else PATH, else ``target/release`` of a repository above the add-on, the working
directory or the open .blend file."""

import os
import shutil

BUILD_HINT = {
    "sfmeval": "cargo build --release -p sfmeval-cli",
    "sfmeval-runner": "cargo build --release -p sfmeval-runner",
}


class ToolMissing(RuntimeError):
    """A binary is not found; the message says what to build or set."""


def _repo_candidates(extra_dirs):
    seen = set()
    for start in list(extra_dirs) + [os.getcwd(), os.path.dirname(os.path.abspath(__file__))]:
        d = os.path.abspath(start) if start else None
        while d and d not in seen:
            seen.add(d)
            yield os.path.join(d, "target", "release")
            parent = os.path.dirname(d)
            if parent == d:
                break
            d = parent


def find(name, preferred="", extra_dirs=()):
    """Absolute path of binary `name` (``sfmeval`` or ``sfmeval-runner``) or ToolMissing."""
    if preferred:
        p = os.path.abspath(os.path.expanduser(preferred))
        if os.path.isfile(p) and os.access(p, os.X_OK):
            return p
        raise ToolMissing("%s: the path set in the add-on preferences, %s, is not an executable "
                          "file (build it with `%s` or fix the path)" % (name, p, BUILD_HINT[name]))
    p = shutil.which(name)
    if p:
        return p
    for d in _repo_candidates(extra_dirs):
        p = os.path.join(d, name)
        if os.path.isfile(p) and os.access(p, os.X_OK):
            return p
    raise ToolMissing("%s not found on PATH nor in a repository's target/release: build it with "
                      "`%s` in the sfmeval repository, or set its path in the add-on preferences"
                      % (name, BUILD_HINT[name]))
