#!/usr/bin/env python3
"""Flicker and frame-to-frame change of a recorded run (issue 37).

    scripts/flicker.py DIR [--from 60 --to 119]

Reads DIR/frame_NNNN.png. For each frame t in [from+1, to-1], the second
temporal difference |I(t) - (I(t-1) + I(t+1)) / 2| per pixel and channel (8-bit
sRGB values, as a player sees them): a slow, smooth change of light gives about
0, a value that alternates frame to frame gives half its swing. Prints the
share of pixels whose second difference exceeds 2/255 in some channel, and the
share whose value changes by more than 2/255 from one frame to the next.
Needs python3-numpy and python3-pil (Debian).
"""
import argparse
import pathlib
import sys

import numpy as np
from PIL import Image


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--from", dest="first", type=int, default=60)
    ap.add_argument("--to", dest="last", type=int, default=119)
    ap.add_argument("--threshold", type=float, default=2.0, help="in 8-bit steps")
    a = ap.parse_args()
    d = pathlib.Path(a.dir)
    frames = []
    for t in range(a.first, a.last + 1):
        p = d / f"frame_{t:04d}.png"
        if not p.exists():
            sys.exit(f"flicker.py: {p}: no such frame")
        frames.append(np.asarray(Image.open(p).convert("RGB"), dtype=np.float32))
    f = np.stack(frames)
    second = np.abs(f[1:-1] - 0.5 * (f[:-2] + f[2:])).max(axis=3)
    step = np.abs(f[1:] - f[:-1]).max(axis=3)
    print(f"frames {a.first}-{a.last} of {d}: second difference > {a.threshold:g}/255 in "
          f"{100 * (second > a.threshold).mean():.4f} % of pixels; frame-to-frame change > {a.threshold:g}/255 in "
          f"{100 * (step > a.threshold).mean():.4f} %")


if __name__ == "__main__":
    main()
