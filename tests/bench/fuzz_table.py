#!/usr/bin/env python3
"""The fuzzing figures of docs/reliability.md from tests/fuzz/run_fuzzers.sh's summary (written to
BUILD/fuzz/summary.txt: one line per target with its executions, libFuzzer's edge coverage `cov`,
its features `ft` and the verdict), as a two-column markdown table, and the count of targets and
findings:

    ./setup.sh fuzz 10
    tests/bench/fuzz_table.py build-san/fuzz/summary.txt

A benchmark's table, not a test: nothing asserts."""
import sys


def read(path):
    rows = []
    with open(path) as f:
        for line in f:
            words = line.split()
            if len(words) < 5 or words[0] == "target":
                continue
            rows.append(words[:4] + [" ".join(words[4:])])
    return rows


def count(text):
    return f"{int(text):,}" if text.isdigit() else text


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: fuzz_table.py SUMMARY")
    try:
        rows = read(sys.argv[1])
    except OSError as e:
        sys.exit(f"bench: {sys.argv[1]}: {e.strerror}")
    if not rows:
        sys.exit(f"bench: {sys.argv[1]}: no target lines")
    half = (len(rows) + 1) // 2
    left, right = rows[:half], rows[half:]
    print("| target | executions | cov | target | executions | cov |")
    print("| --- | ---: | ---: | --- | ---: | ---: |")
    for i, row in enumerate(left):
        cells = [f"`{row[0]}`", count(row[1]), row[2]]
        if i < len(right):
            cells += [f"`{right[i][0]}`", count(right[i][1]), right[i][2]]
        else:
            cells += ["", "", ""]
        print("| " + " | ".join(cells) + " |")
    found = [r for r in rows if r[4] != "ok"]
    print()
    print(f"{len(rows)} targets; " + (f"{len(found)} not ok: " + ", ".join(
        f"{r[0]} ({r[4]})" for r in found) if found else "no finding"))


if __name__ == "__main__":
    main()
