"""docs/scenes/preview_strip.png: three previews of one render, side by side.

    python scripts/make_preview_strip.py [--scene cornell] [--width 200]

Renders SCENE with the numpy backend at 64 spp and keeps the previews that hold
exactly 1, 8 and 64 samples in every pixel (rtpy.render's preview= function), as
`--preview` would have written them while the image sharpened.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from PIL import Image

import rtpy

OUT = Path(__file__).resolve().parent.parent / "docs" / "scenes" / "preview_strip.png"
KEEP = (1, 8)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default="cornell")
    parser.add_argument("--width", type=int, default=200)
    args = parser.parse_args()
    scene = rtpy.load_scene(args.scene)
    frames = {}

    def keep(image: rtpy.RenderedImage) -> None:
        if image.samples_min == image.samples_max in KEEP:
            frames[image.samples_min] = image.to_pil()

    final = rtpy.render(scene, width=args.width, spp=64, backend="numpy", seed=1,
                        preview=keep, preview_seconds=0)  # fmt: skip
    frames[64] = final.to_pil()
    strip = Image.new("RGB", (3 * final.width + 8, final.height), "white")
    for k, spp in enumerate(sorted(frames)):
        strip.paste(frames[spp], (k * (final.width + 4), 0))
    strip.save(OUT)
    print(f"wrote {OUT}: previews at {sorted(frames)} spp")


if __name__ == "__main__":
    main()
