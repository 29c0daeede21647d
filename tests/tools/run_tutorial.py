#!/usr/bin/env python3
"""Follows a tutorial page of docs/ as a reader would: runs its shell blocks, in order, as written.

Every fenced block marked ```sh is run, one bash script for the page (`set -euo pipefail`, so the
first failing command fails the test), in a fresh folder holding a link to the repository's
assets/ (the tutorials' `assets/demo/drive.tum`), with `gvio` the binary under test. A page
steers this with HTML comments, which the site does not show:

    <!-- tutorial: skip -->       the next sh block is not run (a download, a GUI, a long run)
    <!-- tutorial: run CMD -->    CMD runs here, unseen: it stands in for what the reader has
                                  and this machine does not (their own KITTI download, their
                                  reference trajectory, their Slurm cluster), never for a step
                                  the page shows; $GVIO_SOURCE is the repository. A CMD that
                                  exits 77 skips the page (exit 77): what it stands in for
                                  cannot be had here (no Slurm to start a cluster with)

A page with no sh block, or whose directives are malformed, fails: a tutorial that silently ran
nothing would pass forever.

    tests/tools/run_tutorial.py docs/tutorials/kitti-raw.md --gvio build/app/gvio [--keep DIR]
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
DIRECTIVE = re.compile(r"<!-- tutorial: (skip|run) ?(.*?) -->$")


def script_of(page):
    """The bash script a page's sh blocks and directives make, and how many blocks it runs."""
    lines = open(page).read().splitlines()
    out, blocks, skip, i = [], 0, False, 0
    while i < len(lines):
        line = lines[i].strip()
        m = DIRECTIVE.match(line)
        if line.startswith("<!-- tutorial:") and not m:
            sys.exit(f"{page}:{i + 1}: not a directive: {line}")
        if m and m.group(1) == "skip":
            skip = True
        elif m:
            if not m.group(2):
                sys.exit(f"{page}:{i + 1}: 'tutorial: run' needs a command")
            out.append(f"# {os.path.basename(page)}:{i + 1} (unseen)\n{m.group(2)}")
        elif line.startswith("```"):
            lang = line[3:].strip()
            end = i + 1
            while end < len(lines) and not lines[end].strip().startswith("```"):
                end += 1
            if end == len(lines):
                sys.exit(f"{page}:{i + 1}: a code block that never ends")
            indent = len(lines[i]) - len(lines[i].lstrip())
            body = [ln[indent:] for ln in lines[i + 1:end]]
            if lang == "sh" and not skip:
                out.append(f"# {os.path.basename(page)}:{i + 2}\n" + "\n".join(body))
                blocks += 1
            if lang == "sh":
                skip = False
            i = end
        i += 1
    return "\n".join(out) + "\n", blocks


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("page")
    parser.add_argument("--gvio", required=True, help="the gvio binary the tutorial calls")
    parser.add_argument("--keep", help="run in this folder (made empty) and keep it")
    args = parser.parse_args()
    script, blocks = script_of(args.page)
    if blocks == 0:
        sys.exit(f"{args.page}: no sh block to run")
    gvio = os.path.abspath(args.gvio)
    if not os.access(gvio, os.X_OK):
        sys.exit(f"{gvio}: not an executable")
    work = args.keep or tempfile.mkdtemp(prefix="gvio_tutorial_")
    if args.keep:
        shutil.rmtree(work, ignore_errors=True)
        os.makedirs(work)
    os.symlink(os.path.join(ROOT, "assets"), os.path.join(work, "assets"))
    bin_dir = os.path.join(work, ".bin")
    os.makedirs(bin_dir)
    os.symlink(gvio, os.path.join(bin_dir, "gvio"))
    env = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ.get("PATH", ""),
               GVIO_SOURCE=ROOT)
    full = "set -euo pipefail\nset -x\n" + script
    print(f"run_tutorial: {args.page}: {blocks} blocks in {work}", flush=True)
    rc = subprocess.run(["bash", "-c", full], cwd=work, env=env).returncode
    if not args.keep:
        shutil.rmtree(work, ignore_errors=True)
    if rc == 77:
        print(f"run_tutorial: {args.page}: skipped (a stand-in step cannot run here)")
        sys.exit(77)
    if rc != 0:
        print(f"run_tutorial: {args.page}: a command failed (exit {rc}); the trace above "
              "shows which", file=sys.stderr)
        sys.exit(1)
    print(f"run_tutorial: {args.page}: every block ran")


if __name__ == "__main__":
    main()
