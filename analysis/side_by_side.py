#!/usr/bin/python3
"""Puts PNGs side by side, each under its own title, into one PNG.

    /usr/bin/python3 analysis/side_by_side.py OUT.png TITLE=IN.png [TITLE=IN.png ...]
        [--width-per-panel INCHES]

For gallery comparisons (scripts/gallery.sh), e.g. the pinned block without
and with a grain; the panels are the pictures analysis/render.py drew.
"""

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mimage  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("panels", nargs="+", help="TITLE=PNG")
    parser.add_argument("--width-per-panel", type=float, default=4.0)
    args = parser.parse_args()
    panels = []
    for spec in args.panels:
        title, sep, path = spec.rpartition("=")
        if not sep or not title:
            parser.error(f"panel '{spec}': expected TITLE=PNG")
        panels.append((title, mimage.imread(path)))
    height = args.width_per_panel * max(im.shape[0] / im.shape[1] for _, im in panels) + 0.4
    fig, axes = plt.subplots(1, len(panels), figsize=(args.width_per_panel * len(panels), height))
    for ax, (title, image) in zip(axes if len(panels) > 1 else [axes], panels):
        ax.imshow(image)
        ax.set_title(title, fontsize=10)
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    plt.close(fig)
    print(args.out)


if __name__ == "__main__":
    main()
