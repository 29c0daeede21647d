#!/usr/bin/env python3
"""The benchmark tables of the docs, generated from the benchmark scripts' committed outputs.

A benchmark's output is committed as tests/bench/results/NAME.txt: a header saying how it was
made (the command, the commit of the binary, the date, the machine), a line '---', then what the
script printed, as it printed it. A page shows it between two markers

    <!-- bench: NAME -->
    ...generated...
    <!-- /bench: NAME -->

which `render` fills with that output and the line saying how it was made; `render --check` fails
(exit 1) when a page differs from what the committed outputs give (a table edited by hand, or an
output recorded and not rendered). `plots DIR` draws the figures the pages show from the same
outputs (SVG, matplotlib), into a folder the site build fills (`./setup.sh docs`).

    tests/tools/bench_results.py record NAME --command 'CMD' --output FILE [--commit SHA]
    tests/tools/bench_results.py render [--check]
    tests/tools/bench_results.py plots docs/benchmarks/plots
"""
import argparse
import datetime
import os
import platform
import re
import subprocess
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
RESULTS = os.path.join(ROOT, "tests", "bench", "results")
DOCS = os.path.join(ROOT, "docs")
BLOCK = re.compile(r"(<!-- bench: ([\w-]+) -->\n)(.*?)(<!-- /bench: \2 -->)", re.S)
HEADER_KEYS = ("command", "commit", "date", "machine")


def fail(message):
    print(f"bench_results: {message}", file=sys.stderr)
    sys.exit(2)


def machine():
    cores = os.cpu_count() or 0
    model = ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{cores} cores{', ' + model if model else ''} ({platform.system()})"


def read_result(name):
    """(header dict, body text) of tests/bench/results/NAME.txt."""
    path = os.path.join(RESULTS, f"{name}.txt")
    try:
        with open(path) as f:
            text = f.read()
    except OSError as e:
        fail(f"{path}: {e.strerror}")
    head, sep, body = text.partition("\n---\n")
    if not sep:
        fail(f"{path}: no '---' line after the header")
    header = {}
    for number, line in enumerate(head.splitlines(), 1):
        key, colon, value = line.partition(": ")
        if not colon or key not in HEADER_KEYS:
            fail(f"{path}:{number}: expected one of {', '.join(HEADER_KEYS)} as 'key: value'")
        header[key] = value
    missing = [k for k in HEADER_KEYS if k not in header]
    if missing:
        fail(f"{path}: the header lacks {', '.join(missing)}")
    return header, body.strip("\n")


def record(args):
    try:
        with open(args.output) as f:
            body = f.read().strip("\n")
    except OSError as e:
        fail(f"{args.output}: {e.strerror}")
    if not body:
        fail(f"{args.output}: empty (the benchmark printed nothing)")
    commit = args.commit or subprocess.run(
        ["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
        check=True).stdout.strip()
    date = args.date or datetime.date.today().isoformat()
    os.makedirs(RESULTS, exist_ok=True)
    path = os.path.join(RESULTS, f"{args.name}.txt")
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(f"command: {args.command}\ncommit: {commit}\ndate: {date}\n"
                f"machine: {args.machine or machine()}\n---\n{body}\n")
    os.replace(tmp, path)
    print(f"bench_results: wrote {os.path.relpath(path, ROOT)}")


def paragraphs(body):
    """The script's lines as markdown shows them: each text line a paragraph of its own (markdown
    would join consecutive lines), tables kept together."""
    lines, out = body.splitlines(), []
    for i, line in enumerate(lines):
        out.append(line)
        following = lines[i + 1] if i + 1 < len(lines) else ""
        if line and not line.startswith("|") and following and not following.startswith("|"):
            out.append("")
    return "\n".join(out)


def block_text(name):
    header, body = read_result(name)
    return (f"{paragraphs(body)}\n\nMade by `{header['command']}` with the build of commit {header['commit']}"
            f" on {header['date']} ({header['machine']}); the output is "
            f"`tests/bench/results/{name}.txt`.\n")


def pages():
    for folder, _, files in os.walk(DOCS):
        for file in sorted(files):
            if file.endswith(".md"):
                yield os.path.join(folder, file)


def render(args):
    stale, used = [], set()
    for page in sorted(pages()):
        with open(page) as f:
            text = f.read()

        def fill(m):
            used.add(m.group(2))
            return m.group(1) + block_text(m.group(2)) + m.group(4)

        new = BLOCK.sub(fill, text)
        if new == text:
            continue
        rel = os.path.relpath(page, ROOT)
        if args.check:
            stale.append(rel)
        else:
            with open(page + ".tmp", "w") as f:
                f.write(new)
            os.replace(page + ".tmp", page)
            print(f"bench_results: rendered {rel}")
    recorded = {f[:-4] for f in os.listdir(RESULTS) if f.endswith(".txt")}
    unused = sorted(recorded - used)
    if unused:
        fail(f"outputs no page shows: {', '.join(unused)} (tests/bench/results)")
    if stale:
        print("bench_results: these pages differ from the committed benchmark outputs: "
              f"{', '.join(stale)}; run tests/tools/bench_results.py render", file=sys.stderr)
        sys.exit(1)


# --- plots -----------------------------------------------------------------------------------

def tables(body):
    """Every markdown table of a script's output, as (header cells, rows of cells)."""
    out, current = [], None
    for line in body.splitlines():
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if current is None:
                current = (cells, [])
            elif not all(re.fullmatch(r"-+", c.replace(" ", "")) for c in cells):
                current[1].append(cells)
        elif current is not None:
            out.append(current)
            current = None
    if current is not None:
        out.append(current)
    return out


def number(cell, pattern=r"-?[0-9]+\.?[0-9]*"):
    m = re.search(pattern, cell)
    return float(m.group(1) if m and m.groups() else m.group(0)) if m else None


def column(table, title):
    head, rows = table
    if title not in head:
        fail(f"no column '{title}' in a table (columns: {', '.join(head)})")
    i = head.index(title)
    return [row[i] if i < len(row) else "" for row in rows]


def bars(path, labels, series, ylabel, title, target=None, target_label=None):
    import matplotlib
    matplotlib.use("svg")
    import matplotlib.pyplot as plt
    plt.rcParams["svg.hashsalt"] = "gvio"
    fig, ax = plt.subplots(figsize=(9, 3.6))
    width = 0.8 / max(1, len(series))
    for k, (name, values) in enumerate(series):
        xs = [i + (k - (len(series) - 1) / 2) * width for i in range(len(labels))]
        ax.bar(xs, [v if v is not None else 0 for v in values], width, label=name)
    if target is not None:
        ax.axhline(target, color="black", linestyle="--", linewidth=1, label=target_label)
    ax.set_xticks(range(len(labels)))
    ax.set_xticklabels(labels, rotation=30, ha="right", fontsize=8)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, metadata={"Date": None})
    plt.close(fig)


def plot_image_check(path):
    (table,) = tables(read_result("image_check_matrix")[1])[:1]
    labels = [f"{s} {n}" for s, n in zip(column(table, "style"), column(table, "seed"))]
    flagged = [number(c, r"\(([0-9.]+) %\)") for c in column(table, "true poses: flagged")]
    bars(path, labels, [("true poses: keyframes flagged", flagged)], "% of keyframes",
         "The image check with true poses, per world and seed", 1.0, "target: 1 %")


def plot_real_gnss(path):
    table = tables(read_result("real_gnss")[1])[0]
    window, solution = column(table, "window"), column(table, "solution")
    rows = [i for i, s in enumerate(solution) if s.lower().startswith("spp")]
    labels = [window[i] for i in rows]
    series = []
    for name in ("raw fixes", "floor", "graph", "KF (paper)"):
        values = column(table, name)
        series.append((name, [number(values[i]) for i in rows]))
    bars(path, labels, series, "horizontal RMS (m)", "Real SPP errors (Nagoya), per window")


def plot_vio_matrix(path):
    table = tables(read_result("vio_matrix_stereo_imu")[1])[0]
    rows = [i for i, seed in enumerate(column(table, "seed")) if seed]  # not the "worst" rows
    style, seed = column(table, "style"), column(table, "seed")
    labels = [f"{style[i]} {seed[i]}" for i in rows]
    pct = [number(column(table, "stereo-imu APE %")[i]) for i in rows]
    bars(path, labels, [("stereo+IMU APE", pct)], "APE RMSE (% of the path)",
         "Pure VIO per world and seed (60 s drives)", 0.10, "target: 0.10 %")


PLOTS = {"image_check_matrix": plot_image_check, "real_gnss": plot_real_gnss,
         "vio_matrix_stereo_imu": plot_vio_matrix}


def plots(args):
    os.makedirs(args.dir, exist_ok=True)
    for name, draw in PLOTS.items():
        if os.path.exists(os.path.join(RESULTS, f"{name}.txt")):
            draw(os.path.join(args.dir, f"{name}.svg"))
            print(f"bench_results: drew {os.path.join(args.dir, name + '.svg')}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="what", required=True)
    r = sub.add_parser("record", help="commit a benchmark's output")
    r.add_argument("name")
    r.add_argument("--command", required=True, help="the command that printed it")
    r.add_argument("--output", required=True, help="the file holding what it printed")
    r.add_argument("--commit", help="the commit its binary was built from (default HEAD)")
    r.add_argument("--date", help="when it ran (default today)")
    r.add_argument("--machine", help="where it ran (default this machine)")
    d = sub.add_parser("render", help="fill the pages' benchmark blocks")
    d.add_argument("--check", action="store_true", help="only say whether a page is stale")
    p = sub.add_parser("plots", help="draw the pages' figures (SVG)")
    p.add_argument("dir")
    args = parser.parse_args()
    {"record": record, "render": render, "plots": plots}[args.what](args)


if __name__ == "__main__":
    main()
