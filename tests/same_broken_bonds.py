#!/usr/bin/env python3
"""Do two checkpoints hold the same broken bonds? Each may be one file or an index over parts
(its `.parts/part_*.h5`). Bonds are compared as unordered pairs of global ids.

    python3 tests/same_broken_bonds.py A.h5 B.h5

Prints both counts and the differences; exits 1 if the sets differ. Needs h5py and numpy."""
import glob
import sys

import h5py
import numpy as np


def broken(checkpoint):
    parts = sorted(glob.glob(checkpoint[: -len(".h5")] + ".parts/part_*.h5"))
    files = parts or [checkpoint]
    pairs = []
    for f in files:
        with h5py.File(f, "r") as h:
            pairs.append(h["broken_bonds"][:].astype(np.int64))
    b = np.sort(np.concatenate(pairs), axis=1)
    return set(map(tuple, b.tolist())), len(files)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    a, na = broken(sys.argv[1])
    b, nb = broken(sys.argv[2])
    print(f"{sys.argv[1]}: {len(a)} broken bonds in {na} file(s)")
    print(f"{sys.argv[2]}: {len(b)} broken bonds in {nb} file(s)")
    print(f"same broken bonds: {a == b} (only in the first: {len(a - b)}, only in the second: {len(b - a)})")
    sys.exit(0 if a == b else 1)


if __name__ == "__main__":
    main()
