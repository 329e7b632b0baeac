"""Render the README's preview image of every bundled scene into docs/scenes/.

    python scripts/render_previews.py [--workers N] [NAME ...]

The settings per scene are below (small images; pure Python is not fast).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import rtpy
from rtpy.io.bundled import bundled_scenes

DOCS = Path(__file__).resolve().parent.parent / "docs" / "scenes"

# width, spp per scene; everything else comes from the scene file. Scenes listed in
# NUMPY render with the numpy backend (rough glass needs many samples to look smooth;
# week06_ladder's preview is made with its ladder strip, also on the numpy backend).
SETTINGS = {
    "cornell": (160, 128),
    "rtiow_cover": (240, 16),
    "week05_point_light": (320, 32),
    "week07_textures": (320, 32),
    "week08_three_balls": (320, 64),
    "week08_phong": (320, 32),
    "week08_blinn": (320, 32),
    "week08_cook_torrance": (320, 32),
    "material_gallery": (400, 32),
    "teapot": (320, 32),
    "week08_rough_glass": (320, 1024),
    "week06_ladder": (320, 64),
}
NUMPY = {"week08_rough_glass", "week06_ladder"}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    DOCS.mkdir(parents=True, exist_ok=True)
    for name, _ in bundled_scenes():
        if args.names and name not in args.names:
            continue
        width, spp = SETTINGS.get(name, (240, 32))
        backend = "numpy" if name in NUMPY else "scalar"
        image = rtpy.render(
            rtpy.load_scene(name),
            width=width,
            spp=spp,
            workers=args.workers,
            quiet=False,
            backend=backend,
        )
        out = image.save(DOCS / f"{name}.png")
        stats = image.stats
        print(f"{out}: {width} px, {spp} spp, {stats['seconds']:.0f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
