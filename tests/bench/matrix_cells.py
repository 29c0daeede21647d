"""The cells of tests/bench/vio_matrix.sh output folders, for the tables that read its runs
(time_offset_table.py, rpe_matrix.py, init_tilt_table.py): each BENCH_OUT holds one folder per
cell, STYLE_seedN, with one folder per VIO mode inside."""
import os
import re

CELL = re.compile(r"(.+)_seed(\d+)")


def cells(outs, mode, needs=None):
    """(cell folder, style, seed, run folder) of every cell of the given output folders, in order,
    whose `mode` run exists (and holds the file `needs`, when given)."""
    for out in outs:
        for cell in sorted(os.listdir(out)):
            m = CELL.fullmatch(cell)
            run = os.path.join(out, cell, mode)
            if not m or not os.path.isdir(run):
                continue
            if needs and not os.path.isfile(os.path.join(run, needs)):
                continue
            yield os.path.join(out, cell), m.group(1), m.group(2), run
