#!/usr/bin/python3
"""Tile a shear sample file (docs/outputs.md, "Sample files") K times along the period:
every row, walls included, is repeated with x shifted by 0, L, ..., (K-1) L, so a dense,
sheared sample of period L becomes one of period K L with K times the grains, without a
new compaction (which at 64 000 grains takes longer than the measurement it prepares and
can collapse past a radius: docs/performance.md). The copies start identical; a run from
the tiled sample should shear a while before it is measured.

    /usr/bin/python3 bench/tile_sample.py RUN/sample_final.csv L K > tiled.csv

L is the run's Shear cell/Length (m); run the tiled sample with Length = K L.
"""
import sys


def main(path, length, copies):
    with open(path) as f:
        header, *rows = f.read().splitlines()
    if not header.startswith("x,y,r,body"):
        sys.exit(f"{path}:1: expected the header 'x,y,r,body[,vx,vy,spin]', found '{header}'")
    print(header)
    for k in range(copies):
        for line, row in enumerate(rows, start=2):
            cells = row.split(",")
            try:
                x = float(cells[0])
            except ValueError:
                sys.exit(f"{path}:{line}: column x: expected a number, found '{cells[0]}'")
            print(",".join([repr(x + k * length)] + cells[1:]))


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit("usage: tile_sample.py SAMPLE.csv LENGTH COPIES > TILED.csv")
    main(sys.argv[1], float(sys.argv[2]), int(sys.argv[3]))
