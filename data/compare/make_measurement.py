#!/usr/bin/env python3
"""Turn a simulated grid (simform run --grid-out) into a stand-in "measurement" for the
worked example of gsa compare (README.md here): the part misplaced by a rigid motion the
comparison does not know, digitisation noise on every position, some marks not digitised
on the formed part and a few gross blunders. Standard library only; fixed seed.

    python3 data/compare/make_measurement.py SIM_GRID.csv OUT.csv
"""
import math
import random
import sys

NOISE_MM = 0.02          # standard deviation per coordinate, both states
MISSING = 0.05           # fraction of marks without a deformed position
BLUNDERS = 3             # marks digitised 1.5 mm off on the formed part
ANGLE_DEG = 4.0          # rigid misplacement of the formed part: rotation ...
AXIS = (0.3, -0.4, 0.87)  # ... about this axis ...
SHIFT = (7.5, -4.0, 2.5)  # ... then this translation (mm)
SEED = 14


def rotation(axis, angle):
    n = math.sqrt(sum(a * a for a in axis))
    x, y, z = (a / n for a in axis)
    c, s = math.cos(angle), math.sin(angle)
    return [[c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s],
            [y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s],
            [z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c)]]


def main(src, dst):
    rng = random.Random(SEED)
    r = rotation(AXIS, math.radians(ANGLE_DEG))
    lines = open(src).read().splitlines()
    header = next(i for i, l in enumerate(lines) if l and not l.startswith('#'))
    cols = lines[header].split(',')
    rows = [dict(zip(cols, l.split(','))) for l in lines[header + 1:] if l.strip()]
    missing = set(rng.sample(range(len(rows)), int(MISSING * len(rows))))
    blunders = set(rng.sample([k for k in range(len(rows)) if k not in missing], BLUNDERS))
    with open(dst, 'w') as out:
        out.write('# stand-in measurement made by data/compare/make_measurement.py from %s:\n' % src)
        out.write('# rotated %g deg about (%g, %g, %g) and shifted (%g, %g, %g) mm; noise %g mm; '
                  '%d marks not digitised on the part; %d blunders of 1.5 mm\n'
                  % ((ANGLE_DEG,) + AXIS + SHIFT + (NOISE_MM, len(missing), len(blunders))))
        out.write('# units: mm\n')
        out.write(','.join(cols) + '\n')
        for k, row in enumerate(rows):
            for key in ('X', 'Y', 'Z'):
                row[key] = '%.4f' % (float(row[key]) + rng.gauss(0, NOISE_MM))
            x = [float(row[key]) for key in ('x', 'y', 'z')]
            y = [sum(r[i][j] * x[j] for j in range(3)) + SHIFT[i] + rng.gauss(0, NOISE_MM) for i in range(3)]
            if k in blunders:
                y[2] += 1.5
            for key, v in zip(('x', 'y', 'z'), y):
                row[key] = '' if k in missing else '%.4f' % v
            out.write(','.join(row[c] for c in cols) + '\n')


if __name__ == '__main__':
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
