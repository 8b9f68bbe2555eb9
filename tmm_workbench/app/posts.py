"""Post-processing headless: FreeCAD's post modules, plus TMM's own post folder.

`Init.py` adds `POST_DIR` to `PathPreferences.searchPathsPost()` so TMM's posts are offered in a
Job like the stock ones and load like them (compat.load_post on every FreeCAD version).
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any, Optional, Sequence

from tmm_workbench.core.errors import TmmError

POST_DIR = str(Path(__file__).resolve().parent / "posts")
# 4 decimals of mm for the stock posts: at their default 3, the rounding alone puts 3-axis surface finishing
# up to 0.024 mm into steep CL profiles (tests/core/test_linear_moves.py)
DEFAULT_ARGS = {name: "--no-show-editor --precision 4" for name in ("linuxcnc", "grbl", "tmm_linuxcnc", "tmm_grbl")}


def install_post_dir() -> None:
    """Wrap PathPreferences.searchPathsPost once so it also returns POST_DIR (FreeCAD 0.20 has no
    other hook for an add-on's posts)."""
    from tmm_workbench.app.compat import PathPreferences

    original = PathPreferences.searchPathsPost
    if getattr(original, "_tmm_wrapped", False):
        return

    def searchPathsPost() -> list[str]:
        paths = list(original())
        if POST_DIR not in paths:
            paths.append(POST_DIR)
        return paths

    searchPathsPost._tmm_wrapped = True  # type: ignore[attr-defined]
    PathPreferences.searchPathsPost = searchPathsPost


def export(post: str, objects: Sequence[Any], gcode_path: Optional[str | os.PathLike] = None,
           args: Optional[str] = None) -> str:
    """G-code for `objects` (tool controllers and ops, in order) through the post `post`.

    Writes `gcode_path` when given. Some stock posts (grbl) only write a file and return None, so
    the text is always read back from the file written.
    """
    from tmm_workbench.app.compat import load_post

    install_post_dir()
    try:
        processor = load_post(post)
    except ImportError as exc:
        raise TmmError(f"post-processor '{post}' not found ({exc})") from exc
    args = DEFAULT_ARGS.get(post, "--no-show-editor") if args is None else args
    target = str(gcode_path) if gcode_path else None
    tmp = None
    if target is None:
        fd, tmp = tempfile.mkstemp(suffix=".ngc", prefix="tmm_")
        os.close(fd)
        target = tmp
    try:
        result = processor.export(list(objects), target, args)
        text = Path(target).read_text() if Path(target).is_file() else ""
        if not text and isinstance(result, str):
            text = result
        if not text:
            raise TmmError(f"post-processor '{post}' produced no G-code (arguments {args!r})")
        return text
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.remove(tmp)
