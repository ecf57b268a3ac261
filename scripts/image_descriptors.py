#!/usr/bin/python3
"""Place descriptors for a folder of images, one row per image in file-name order, written as
.npy: what `ratslam evaluate --map-descriptors/--query-descriptors` reads. A stand-in for a
learnt descriptor (NetVLAD and the like), made with NumPy alone so that the benchmark runs on a
bare Debian machine: a histogram of oriented gradients (Dalal and Triggs, CVPR 2005) over a grid
of cells, each cell's histogram weighted by gradient magnitude and the whole vector
L2-normalised, then centred on the folder's mean so that what every image shares (the train's
bonnet, the sky) does not dominate the cosine.

Reads 8-bit PNG (grey, grey+alpha, RGB, RGBA; not interlaced) and binary PGM.
Usage: image_descriptors.py IMAGE_FOLDER OUT.npy [--cells 8x4] [--bins 9] [--no-centre]
"""
import argparse
import os
import struct
import sys
import zlib

import numpy as np

IMAGE_EXTENSIONS = (".png", ".pgm")


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    return b if pb <= pc else c


def read_png(path):
    """Grey levels (height x width, float) of an 8-bit non-interlaced PNG."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG file")
    pos, idat, header = 8, [], None
    while pos + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
        pos += 12 + length
    if header is None:
        raise ValueError(f"{path}: no IHDR chunk")
    width, height, depth, colour, _, _, interlace = header
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(colour)
    if depth != 8 or channels is None or interlace:
        raise ValueError(f"{path}: only 8-bit grey/RGB(A) non-interlaced PNG is read")
    raw = zlib.decompress(b"".join(idat))
    stride = width * channels
    rows = np.zeros((height, stride), dtype=np.int32)
    previous = np.zeros(stride, dtype=np.int32)
    for y in range(height):
        line = raw[y * (stride + 1):(y + 1) * (stride + 1)]
        kind, row = line[0], np.frombuffer(line[1:], dtype=np.uint8).astype(np.int32)
        if kind == 0:
            out = row
        elif kind == 2:
            out = (row + previous) & 255
        elif kind in (1, 3, 4):  # these depend on the pixel to the left: pixel by pixel
            out = np.zeros(stride, dtype=np.int32)
            for x in range(stride):
                left = out[x - channels] if x >= channels else 0
                up = previous[x]
                upper_left = previous[x - channels] if x >= channels else 0
                if kind == 1:
                    predicted = left
                elif kind == 3:
                    predicted = (left + up) // 2
                else:
                    predicted = _paeth(left, up, upper_left)
                out[x] = (row[x] + predicted) & 255
        else:
            raise ValueError(f"{path}: row {y} has unknown filter {kind}")
        rows[y] = out
        previous = out
    pixels = rows.reshape(height, width, channels).astype(np.float64)
    colour_channels = pixels[:, :, :3] if channels >= 3 else pixels[:, :, :1]
    return colour_channels.mean(axis=2)


def read_pgm(path):
    with open(path, "rb") as f:
        data = f.read()
    fields, pos = [], 0
    while len(fields) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos)
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    if fields[0] != b"P5" or int(fields[3]) > 255:
        raise ValueError(f"{path}: only 8-bit binary PGM (P5) is read")
    width, height = int(fields[1]), int(fields[2])
    pixels = np.frombuffer(data[pos + 1:pos + 1 + width * height], dtype=np.uint8)
    return pixels.reshape(height, width).astype(np.float64)


def hog(grey, cells_x, cells_y, bins):
    gy, gx = np.gradient(grey)
    magnitude = np.hypot(gx, gy)
    angle = np.mod(np.arctan2(gy, gx), np.pi)  # unsigned orientation
    bin_of = np.minimum((angle / np.pi * bins).astype(int), bins - 1)
    height, width = grey.shape
    out = np.zeros((cells_y, cells_x, bins))
    ys = np.minimum(np.arange(height) * cells_y // height, cells_y - 1)
    xs = np.minimum(np.arange(width) * cells_x // width, cells_x - 1)
    np.add.at(out, (ys[:, None], xs[None, :], bin_of), magnitude)
    v = out.ravel()
    norm = np.linalg.norm(v)
    return v / norm if norm > 0 else v


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder")
    parser.add_argument("out")
    parser.add_argument("--cells", default="8x4", help="grid of cells, WxH (default 8x4)")
    parser.add_argument("--bins", type=int, default=9, help="orientation bins (default 9)")
    parser.add_argument("--no-centre", action="store_true", help="keep the folder's mean")
    args = parser.parse_args()
    cells_x, cells_y = (int(v) for v in args.cells.split("x"))
    names = sorted(n for n in os.listdir(args.folder) if n.lower().endswith(IMAGE_EXTENSIONS))
    if not names:
        sys.exit(f"{args.folder}: no .png or .pgm images")
    rows = []
    for name in names:
        path = os.path.join(args.folder, name)
        grey = read_png(path) if name.lower().endswith(".png") else read_pgm(path)
        rows.append(hog(grey, cells_x, cells_y, args.bins))
    matrix = np.array(rows, dtype=np.float64)
    if not args.no_centre:
        matrix -= matrix.mean(axis=0)
    # A flat image (a black frame) has no gradient: a tiny constant keeps its row a direction.
    matrix[np.linalg.norm(matrix, axis=1) == 0] = 1e-6
    np.save(args.out, matrix.astype(np.float32))
    print(f"{args.out}: {len(names)} images x {matrix.shape[1]} values", file=sys.stderr)


if __name__ == "__main__":
    main()
