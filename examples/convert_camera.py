#!/usr/bin/env python3
"""Convert a camera file (DJI, Metashape, Pix4D, COLMAP, OpenCV, ...) and undistort points.

    python3 convert_camera.py CAMERA [--format auto] [--model brown_fraser_10] [--out FILE]

Reads a camera in any format aerocal knows (`aerocal.formats()`), converts it into another model
(exactly where the models are equivalent, else a least-squares fit whose residual is printed), and
maps the corners and the centre of the format to the undistorted pixels of an ideal pinhole camera
with the same principal distance and principal point. Exit 2 on bad input, 3 when the conversion's
residual exceeds --max-residual-px.
"""
import argparse
import sys

import numpy as np

import aerocal


def undistort(camera, pixels):
    """Undistorted pixels: the rays (x / c, y / c) on an ideal camera's format (photo y up)."""
    rays = camera.image_to_ray(pixels)
    principal = camera.ray_to_image(np.zeros((1, 2)))[0]  # the pixel of the principal ray
    c_px = camera.principal_distance_px
    return np.column_stack([principal[0] + c_px * rays[:, 0], principal[1] - c_px * rays[:, 1]])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("camera")
    parser.add_argument("--format", default="auto")
    parser.add_argument("--model", default="brown_fraser_10", choices=aerocal.models())
    parser.add_argument("--max-residual-px", type=float, default=0.1)
    parser.add_argument("--out", help="write the converted camera (aerocal YAML)")
    args = parser.parse_args()
    try:
        camera = aerocal.Camera.read(args.camera, format=args.format)
        converted, residual = aerocal.convert_camera(camera, model=args.model)
    except ValueError as error:
        print(error, file=sys.stderr)
        return 2
    print(f"read: {camera!r}")
    print(f"into {args.model}: {residual['summary']}")
    for name, value in converted.params.items():
        print(f"  {name} = {value!r} {converted.units[name]}")
    w, h = camera.width, camera.height
    pixels = np.array([[0.0, 0.0], [w - 1.0, 0.0], [0.0, h - 1.0], [w - 1.0, h - 1.0],
                       [(w - 1) / 2.0, (h - 1) / 2.0]])
    print("pixel (col, row) -> undistorted (col, row)")
    for before, after in zip(pixels, undistort(camera, pixels)):
        print(f"  {before[0]:9.2f} {before[1]:9.2f} -> {after[0]!r} {after[1]!r}")
    if args.out:
        converted.write(args.out, format="aerocal")
        print(f"written: {args.out}")
    if not residual["exact"] and residual["max_px"] > args.max_residual_px:
        print(f"conversion residual {residual['max_px']} px > {args.max_residual_px} px",
              file=sys.stderr)
        return 3
    return 0


if __name__ == "__main__":
    sys.exit(main())
