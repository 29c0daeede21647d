#!/usr/bin/env python3
"""One line per run of tests/bench/vio_matrix.sh: the stereo+IMU APE over its cells (geometric
mean, % of the path) and the cells within the 0.10 % target, read from what the script printed
(its standard output, or a committed tests/bench/results file): its summary lines where it has
them (exact), else the table's rounded APE % column.

    imu_noise_table.py LABEL=TABLE_FILE...

e.g. `assumed=tests/bench/results/vio_matrix_stereo_imu.txt truth:1=out/bench/vio_imu_truth1.txt`:
what the estimator was told of the IMU noise against the drives' own noise (BENCH_IMU_NOISE)."""
import math
import re
import sys

TARGET = 0.10  # % of the path


def cells(text, path):
    """The stereo-imu APE % of each cell (None where it failed) in a vio_matrix table."""
    lines = [ln.strip() for ln in text.splitlines() if ln.strip().startswith("|")]
    if not lines:
        sys.exit(f"imu_noise_table: {path}: no table")
    head = [c.strip() for c in lines[0].strip("|").split("|")]
    try:
        seed_col, pct_col = head.index("seed"), head.index("stereo-imu APE %")
    except ValueError:
        sys.exit(f"imu_noise_table: {path}: no seed and stereo-imu APE % columns")
    out = []
    for ln in lines[2:]:
        row = [c.strip() for c in ln.strip("|").split("|")]
        if len(row) != len(head) or not row[seed_col]:  # the "worst" rows carry no seed
            continue
        try:
            out.append(float(row[pct_col]))
        except ValueError:
            out.append(None)
    return out


print("Stereo+IMU over the matrix's cells: the IMU noise the estimator is told, SE(3)-aligned APE")
print()
print("| the estimator's IMU noise | cells | failed | geometric mean APE (% of the path) "
      f"| within {TARGET:.2f} % |")
print("| --- | --- | --- | --- | --- |")
for arg in sys.argv[1:]:
    label, sep, path = arg.partition("=")
    if not sep:
        sys.exit(f"imu_noise_table: '{arg}' is not LABEL=FILE")
    with open(path) as f:
        text = f.read()
    values = cells(text, path)
    ok = [v for v in values if v is not None and v > 0.0]
    geo = math.exp(sum(math.log(v) for v in ok) / len(ok)) if ok else math.nan
    within = sum(1 for v in ok if v <= TARGET)
    met = re.search(r"^stereo-imu: (\d+) of (\d+) cells meet", text, re.M)
    if met and int(met.group(2)) == len(values):
        within = int(met.group(1))
    mean = re.search(r"^stereo-imu: geometric mean APE ([0-9.]+) %", text, re.M)
    if mean:
        geo = float(mean.group(1))
    print(f"| {label} | {len(values)} | {len(values) - len(ok)} | {geo:.4f} | {within} |")
