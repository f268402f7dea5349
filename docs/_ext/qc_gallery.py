"""sphinx-gallery hooks for qc_control's examples.

The examples write their figures to files with `matplotlib.figure.Figure`
(no pyplot), so the default matplotlib scraper would find nothing. Here
each example gets an output folder under the build directory (its only
argument, as a student gives it), and the scraper collects the PNG files
an example block wrote there. sphinx-gallery names these hooks by their
import path in ``conf.py`` (picklable configuration).
"""

from __future__ import annotations

import shutil
from pathlib import Path

_SEEN: dict[str, set[Path]] = {}


def output_dir(gallery_conf, src_file) -> Path:
    """Where the example ``src_file`` writes during the docs build."""
    return Path(gallery_conf["src_dir"]) / "_build" / "gallery_output" / Path(src_file).stem


def example_argv(gallery_conf, script_vars) -> list[str]:
    """``sys.argv[1:]`` of an example: its output folder, outside the sources."""
    out = output_dir(gallery_conf, script_vars["src_file"])
    shutil.rmtree(out, ignore_errors=True)
    _SEEN[str(out)] = set()
    return [str(out)]


def png_scraper(block, block_vars, gallery_conf) -> str:
    """The PNG files this code block wrote, as figures of the gallery page."""
    from sphinx_gallery.scrapers import figure_rst

    out = output_dir(gallery_conf, block_vars["src_file"])
    seen = _SEEN.setdefault(str(out), set())
    new = sorted(p for p in out.rglob("*.png") if p not in seen) if out.exists() else []
    names = []
    for png, target in zip(new, block_vars["image_path_iterator"]):
        shutil.copyfile(png, target)
        seen.add(png)
        names.append(target)
    return figure_rst(names, gallery_conf["src_dir"])
