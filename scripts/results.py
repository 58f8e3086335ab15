#!/usr/bin/env python3
"""Regenerates every results table and figure of the docs and of each technique's README.

Run through scripts/results.sh (see its header for the options). On lavapipe it writes
docs/results.md, docs/results/*.svg, ssm-techniques/<t>/results.md (+ results/*.svg), the summary
table of README.md and the rankings of docs/choosing.md (derived from docs/results.md's kinds tables:
`--rankings-from docs/results.md` rederives them without a run, `--check-rankings` checks them and
the hand-written claims against the tables); on any other adapter one file, docs/results-<adapter>.md (+ docs/results/<adapter>/),
so that a GPU run lands beside the lavapipe one. Every generated file's first lines name the
command, the adapter, the date and the commit. Nothing here measures anything itself: each table
is the output of an `ssm` command (or a crate's example), copied as it printed it.
"""

import argparse
import csv
import datetime
import difflib
import itertools
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# SSM_BIN: a prebuilt `ssm` (the GPU pack's); else the workspace's release build.
SSM = Path(os.environ.get("SSM_BIN") or ROOT / "target" / "release" / "ssm").resolve()
EXAMPLES_DIR = ROOT / "target" / "release" / "examples"
# The three scenes of the summary table: contact shadows, overlapping penumbrae of many small
# occluders, and thin occluders at varied heights.
SUMMARY_SCENES = ["sphere-cube", "contact", "leaves"]
# The examples whose output a technique README reproduces (crate, example, arguments).
EXAMPLES = {
    "atty": [("ssm-atty", "atty_work", [])],
    "wedges": [("ssm-wedges", "wedges_work", []), ("ssm-bench", "wedges_fig1", []), ("ssm-bench", "wedges_fig12", [])],
}
# The kinds of scene docs/choosing.md discusses: (heading, scene, extra sweep arguments, what it tests).
SCENE_KINDS = [
    ("contact shadows", "contact", [], "a box and a sphere resting on the ground: penumbrae from zero width"),
    ("a large light", "sphere-cube", ["--vary", "scene.light_scale=3"], "overlapping penumbrae of 125 spheres under a light three times the default"),
    ("thin geometry", "ssm-techniques/pvsm/doc/trellis.toml", ["--vary", "scene.light_scale=25"],
     "a trellis of bars 0.04 thick, crossing bars touching, under a light 0.5 wide"),
    ("an interior", "ssm-techniques/vssm/doc/room-lit-from-a-wall.toml", [], "a closed room lit from a wall at a slant, a block and a ball"),
    ("many triangles", "forest:triangles=200000", [], "16 trees of leaf cards, 200,000 triangles"),
]
TECHNIQUES = ["hard", "pcss", "multi-sm", "vssm", "sssm", "atty", "pvsm", "wedges"]
SUMMARY_BEGIN, SUMMARY_END = "<!-- summary -->", "<!-- /summary -->"


def run(command, log, **kwargs):
    """Runs `command` (a list) from the workspace root, echoing it; returns its stdout."""
    print("+ " + " ".join(map(str, command)), file=sys.stderr, flush=True)
    started = datetime.datetime.now()
    result = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, **kwargs)
    log.write(f"$ {' '.join(map(str, command))}\n{result.stdout}\n{result.stderr}\n")
    if result.returncode != 0:
        sys.exit(f"results: `{' '.join(map(str, command))}` failed ({result.returncode}):\n{result.stderr[-4000:]}")
    print(f"  ({(datetime.datetime.now() - started).total_seconds():.0f} s)", file=sys.stderr, flush=True)
    return result.stdout


def shown(command, scratch=None):
    """A command as a reader would type it from the workspace root (output folders under `out/`)."""
    text = " ".join(str(part) for part in command)
    if scratch is not None:
        text = text.replace(str(scratch), "out")
    return text.replace(str(SSM), "ssm").replace(str(ROOT) + "/", "")


def presets():
    """(name, technique or None, description, scenes) of every sweep preset, as `ssm sweep
    --list-presets` prints them (its second line: `--scene a|b|c  --vary ...`)."""
    listing = subprocess.run([str(SSM), "sweep", "--list-presets"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    found = []
    for line in listing.splitlines():
        match = re.match(r"^([a-z0-9-]+)(?: \[([a-z0-9-]+)\])?: (.*)$", line)
        if match:
            found.append([match.group(1), match.group(2), match.group(3), []])
        scenes = re.match(r"^  --scene (\S+)", line)
        if scenes and found:
            found[-1][3] = scenes.group(1).split("|")
    return [tuple(preset) for preset in found]


def sweep_table(out):
    """sweep.md's table lines (its own first line, the adapter and size, is in our header)."""
    lines = (out / "sweep.md").read_text().splitlines()
    return "\n".join(line for line in lines if line.startswith("|"))


def main():
    parser = argparse.ArgumentParser(prog="scripts/results.sh", description=__doc__)
    parser.add_argument("--width", type=int, default=320, help="image width of every run (default 320)")
    parser.add_argument("--height", type=int, default=240, help="image height of every run (default 240)")
    parser.add_argument("--paper-sizes", action="store_true", help="each preset at its paper's viewport instead of --width/--height")
    parser.add_argument("--frames", type=int, default=5, help="frames timed per point after a warm-up (default 5); tables give their median and interquartile range")
    parser.add_argument("--output-root", type=Path, default=ROOT, help="write the generated files under this folder, laid out as the workspace (default: the workspace itself; elsewhere README.md and docs/choosing.md are left alone)")
    parser.add_argument("--splice-summary", action="store_true", help="only rewrite README.md's summary block (docs/results/summary.md, written by the last run, "
                        "with docs/summary.toml's words and the rankings of docs/results.md) and docs/choosing.md's rankings; runs nothing")
    parser.add_argument("--rankings-from", type=Path, metavar="RESULTS_MD", help="only rederive docs/choosing.md's rankings blocks and README.md's summary "
                        "block from the kinds tables of this results file (docs/results.md); runs nothing")
    parser.add_argument("--check-rankings", nargs="?", const="blocks,claims,summary", metavar="PARTS",
                        help="only check, against the kinds tables of docs/results.md (or --rankings-from's file), the generated rankings blocks "
                        "(blocks), docs/choosing.md's hand-written claims (claims) and docs/summary.toml's (summary); exits 1 on any disagreement")
    parser.add_argument("--only", default="", help="comma-separated parts to run: summary, trade, lights, kinds, and technique names (default: all)")
    args = parser.parse_args(sys.argv[1:])
    only = set(filter(None, args.only.split(",")))
    if args.check_rankings:
        problems = rankings_problems((args.rankings_from or RESULTS).read_text(), set(args.check_rankings.split(",")))
        print("\n".join(problems) if problems else f"rankings: {args.check_rankings} agree with the tables", file=sys.stderr if problems else sys.stdout)
        sys.exit(1 if problems else 0)
    if args.splice_summary or args.rankings_from:
        write_rankings((args.rankings_from or RESULTS).read_text())
        return
    wanted = lambda part: not only or part in only

    command_line = "scripts/results.sh" + "".join(" " + a for a in sys.argv[1:])
    scratch = Path(tempfile.mkdtemp(prefix="ssm-results-"))
    # A fresh ground-truth cache, so that the ground truth's own cost is measured, not read back.
    env = dict(os.environ, SSM_CACHE_DIR=str(scratch / "cache"))
    log = open(scratch / "commands.log", "w")
    print(f"results: scratch folder {scratch} (commands.log has every command's output)", file=sys.stderr)

    listing = json.loads(run([str(SSM), "list", "--format", "json"], log, env=env))
    adapter = listing.get("adapter") or "none"
    commit = subprocess.run(["git", "rev-parse", "--short=12", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    if subprocess.run(["git", "diff", "--quiet", "HEAD"], cwd=ROOT).returncode != 0:
        commit += " (with uncommitted changes)"
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    lavapipe = "llvmpipe" in adapter
    slug = "" if lavapipe else re.sub(r"[^a-z0-9]+", "-", adapter.split("[")[0].lower()).strip("-")
    size_args = [] if args.paper_sizes else ["--width", str(args.width), "--height", str(args.height)]
    pixels = "each preset's paper viewport" if args.paper_sizes else f"{args.width}×{args.height} pixels"

    def header(title):
        return (f"<!-- Generated by `{command_line}`: do not edit; rerun it. -->\n# {title}\n\n"
                f"- Command: `{command_line}` (from the workspace root)\n- Adapter: {adapter}\n- Date: {date}\n"
                f"- Commit: {commit}\n- Images: {pixels}; {args.frames} timed frames per point after a warm-up; "
                "ground truth traced afresh (empty cache).\n\n")

    out_root = args.output_root.resolve()
    docs = out_root / "docs"
    images = docs / "results" / slug if slug else docs / "results"
    images.mkdir(parents=True, exist_ok=True)
    image_link = lambda name: os.path.relpath(images / name, docs)
    body = []
    summary_rows = {}

    # 1. Every technique at its defaults on the summary scenes, with counted work.
    if wanted("summary"):
        body.append("## defaults\n\nEvery technique at its defaults: `ssm compare` on three scenes, times and counted work side by side "
                    "(the error columns are against the ground truth, on the same pixels).\n")
        for scene in SUMMARY_SCENES:
            out = scratch / f"compare-{scene}"
            command = [str(SSM), "compare", "--scene", scene, *(["--width", str(args.width), "--height", str(args.height)] if not args.paper_sizes else []),
                       "--frames", str(args.frames), "--count-work", "--out", str(out)]
            run(command, log, env=env)
            report = (out / "report.md").read_text()
            # Drop the report's own title and its params column (every technique is at its defaults here).
            report = re.sub(r"^# .*\n", "", report)
            report = without_params(report)
            # Its own sections sit under this scene's heading.
            report = re.sub(r"^## ", "#### ", report, flags=re.MULTILINE)
            shutil.copy(out / "passes.svg", images / f"passes-{scene}.svg")
            body.append(f"### `{scene}`\n\n`{shown(command, scratch)}`\n\n{report.strip()}\n\n"
                        f"GPU time per pass: ![passes on {scene}]({image_link(f'passes-{scene}.svg')})\n")
            for row in csv.DictReader(open(out / "results.csv")):
                summary_rows.setdefault(row["technique"], {})[scene] = row

    # 2. The trade plot: every technique's quality knob, error against time and against counted work.
    if wanted("trade"):
        out = scratch / "trade"
        command = [str(SSM), "sweep", "--preset", "trade", *size_args, "--frames", str(args.frames), "--cost", "work", "--out", str(out)]
        run(command, log, env=env)
        shutil.copy(out / "sweep.svg", images / "trade-time.svg")
        shutil.copy(out / "sweep-work.svg", images / "trade-work.svg")
        body.append(f"## trade\n\nThe trade: every technique's quality knob swept, error against time and against counted work.\n\n`{shown(command, scratch)}`\n\n"
                    f"![error against time]({image_link('trade-time.svg')})\n![error against counted work]({image_link('trade-work.svg')})\n\n"
                    f"{sweep_table(out)}\n")

    # 3. Several lights: frame time against the light count.
    if wanted("lights"):
        out = scratch / "lights"
        command = [str(SSM), "sweep", "--preset", "lights", *size_args, "--frames", str(args.frames), "--count-work", "--out", str(out)]
        run(command, log, env=env)
        shutil.copy(out / "sweep.svg", images / "lights.svg")
        body.append(f"## lights\n\nSeveral lights: every technique at its defaults with 1, 2 and 3 copies of the light.\n\n`{shown(command, scratch)}`\n\n![time against lights]({image_link('lights.svg')})\n\n{sweep_table(out)}\n")

    # 4. One scene per kind of scene, every technique at its defaults (docs/choosing.md reads these).
    if wanted("kinds"):
        body.append("## kinds\n\nEvery technique at its defaults on one scene of each kind ([docs/choosing.md](choosing.md) "
                    "ranks them from these tables and draws its advice from the rankings). Under each table: the FLIP of each "
                    "shaded image, then the first places on error, counted work (texel reads and invocations) and time, ties "
                    "decided as docs/choosing.md says.\n")
        for heading, scene, extra, what in SCENE_KINDS:
            out = scratch / f"kind-{re.sub(r'[^a-z0-9]+', '-', heading)}"
            command = [str(SSM), "sweep", "--scene", scene, *extra, *[a for t in TECHNIQUES for a in ("--vary", t)], *size_args,
                       "--frames", str(args.frames), "--count-work", "--out", str(out)]
            run(command, log, env=env)
            rows = [r for r in csv.DictReader(open(out / "sweep.csv")) if r.get("light", "all") == "all"]
            tables = f"{sweep_table(out)}\n\n{flip_table(rows)}"
            body.append(f"### {heading}\n\n{what}.\n\n`{shown(command, scratch)}`\n\n{tables}\n\n{leaders(tables)}\n")

    # 5. The summary table (README.md and the results file), joined with docs/summary.toml's words.
    if summary_rows:
        # Written from docs/results/ (its links resolve there); spliced into README.md with its
        # links made relative to the workspace's root.
        table = summary_table(summary_rows, args, "../../")
        body.insert(0, "## summary\n\nThe README's summary table.\n\n" + summary_table(summary_rows, args, "../") + "\n")
        if lavapipe and out_root == ROOT:
            summary = (f"{table}\nFrom `{command_line}` on {adapter}, {date}, commit {commit} "
                       f"([docs/results.md](../results.md)).\n")
            (docs / "results" / "summary.md").write_text(summary)
    # Written now, and again after each technique on another adapter: a run stopped part-way (a
    # lent GPU's time limit) keeps what it finished.
    target = docs / ("results.md" if lavapipe else f"results-{slug}.md")

    # Each part's sections carry the line of the run that made them, so that a partial run
    # (--only) can replace its own sections in the file and keep the others, each still saying
    # where it came from.
    provenance = f"_Generated by `{command_line}` on {adapter}, {date}, commit {commit}._\n"
    body_sections = lambda: [re.sub(r"^(## [^\n]*\n)", lambda m: m.group(1) + "\n" + provenance, part, count=1) for part in body]

    def write_results():
        if not body:
            return
        sections = part_sections("\n".join(body_sections()))
        if only and target.exists():
            sections = merged_sections(target.read_text(), sections)
        target.write_text(header("Results" + ("" if lavapipe else f" on {adapter}")) + "\n".join(sections))
        print(f"results: wrote {target}", file=sys.stderr)

    write_results()
    # README.md's summary block and docs/choosing.md's rankings, from the file just written.
    if lavapipe and out_root == ROOT and target.exists():
        write_rankings(target.read_text())

    # 6. Each technique's paper presets and the examples that reproduce its cost claims, the
    # technique's results written as soon as they are done.
    by_technique = {}
    for name, technique, description, scenes in presets():
        if technique is not None and wanted(technique):
            by_technique.setdefault(technique, []).append((name, description, scenes))
    for technique in EXAMPLES:
        if wanted(technique):
            by_technique.setdefault(technique, [])
    # Cheaper techniques first, so that a run stopped part-way has the most to show.
    order = ["hard", "pcss", "multi-sm", "vssm", "sssm", "wedges", "atty", "pvsm"]
    for technique, technique_presets in sorted(by_technique.items(), key=lambda item: order.index(item[0]) if item[0] in order else len(order)):
        sections = []
        for name, description, scenes in technique_presets:
            # Every scene the preset names (the paper's kinds of scene), one sweep each.
            for index, scene in enumerate(scenes or [None]):
                label = name if index == 0 else f"{name}-{index + 1}"
                out = scratch / f"preset-{label}"
                scene_args = ["--scene", scene] if len(scenes) > 1 else []
                command = [str(SSM), "sweep", "--preset", name, *scene_args, *size_args, "--frames", str(args.frames), "--count-work", "--out", str(out)]
                run(command, log, env=env)
                sections.append((label, description if index == 0 else f"`{name}` on `{scene}`.", command, out))
        for crate, example, extra in EXAMPLES.get(technique, []):
            binary = EXAMPLES_DIR / example
            command = [str(binary), *extra]
            if not binary.exists():
                # A prebuilt pack carries `ssm` alone: say so in the results rather than skip silently.
                printed = f"Not run: no `{binary.relative_to(ROOT)}` (build it with `cargo build --release -p {crate} --examples`)."
            else:
                printed = run(command, log, env=env)
            command = ["cargo", "run", "--release", "-p", crate, "--example", example, "--", *extra]
            sections.append((example, f"the `{example}` example's output, as printed", command, printed))
        folder = out_root / "ssm-techniques" / technique
        folder.mkdir(parents=True, exist_ok=True)
        text = []
        for name, description, command, out in sections:
            text.append(f"## {name}\n\n{description}\n\n`{shown(command, scratch)}`\n")
            if isinstance(out, str):
                text.append(out.strip() + "\n")
                continue
            plots = folder / "results" / slug if slug else folder / "results"
            plots.mkdir(parents=True, exist_ok=True)
            shutil.copy(out / "sweep.svg", plots / f"{name}.svg")
            text.append(f"![{name}]({os.path.relpath(plots / f'{name}.svg', folder)})\n")
            if (out / "sweep-work.svg").exists():
                shutil.copy(out / "sweep-work.svg", plots / f"{name}-work.svg")
                text.append(f"![{name} in counted work]({os.path.relpath(plots / f'{name}-work.svg', folder)})\n")
            text.append(sweep_table(out) + "\n")
        if lavapipe:
            (folder / "results.md").write_text(header(f"{technique}: reproduced figures") + "\n".join(text))
            print(f"results: wrote {folder / 'results.md'}", file=sys.stderr)
        else:
            body.append(f"## {technique}\n\n" + "\n".join(text).replace("\n## ", "\n### "))
            write_results()
    shutil.rmtree(scratch / "cache", ignore_errors=True)


# ------------------------------------------------------------------------------------------------
# Rankings. docs/choosing.md's generated blocks (one per kind of scene, between
# `<!-- rankings:<kind> -->` lines) and the rankings under the README's summary table are derived
# from the Markdown tables of docs/results.md's `## kinds` section, not from a run's CSVs, so that
# `--rankings-from docs/results.md` rederives them without lavapipe and `--check-rankings` (run by
# ssm-bench/tests/rankings.rs) can tell a block edited by hand, or a hand-written claim of
# docs/choosing.md or docs/summary.toml that the tables contradict.

CHOOSING = ROOT / "docs" / "choosing.md"
SUMMARY_WORDS = ROOT / "docs" / "summary.toml"
RESULTS = ROOT / "docs" / "results.md"
RANKINGS_COMMAND = "scripts/results.py --rankings-from docs/results.md"
# Two FLIP means closer than the sum of their noise floors (the FLIP the ground truth's own noise
# alone shows, `flip_noise`) are tied; in tables without a floor, two within this fraction of the
# lower (a stand-in tolerance, and the generated text says so).
FLIP_TOLERANCE = 0.05
# The groups a claim may rank within (`**Lowest error among the soft techniques: ...**`).
RANKING_GROUPS = {
    "soft techniques": [t for t in TECHNIQUES if t != "hard"],
    "shadow-map techniques": [t for t in TECHNIQUES if t != "wedges"],
    "baselines": ["hard", "pcss", "multi-sm", "vssm"],
}
RANKING_GROUP_NOTES = {"shadow-map techniques": " (`wedges` is the only object-space technique)"}
# What a claim may rank by, as written: (measure, whether the worst comes first).
CLAIM_MEASURES = {
    "lowest error": ("error", False), "most accurate": ("error", False),
    "highest error": ("error", True), "least accurate": ("error", True),
    "lowest flip": ("flip", False), "highest flip": ("flip", True),
    "least work": ("work", False), "most work": ("work", True),
    "least time": ("time", False), "fastest": ("time", False),
    "most time": ("time", True), "slowest": ("time", True),
    "on the error–work front": ("front", False),
}
CLAIM = re.compile(r"(?i)^(?P<measure>" + "|".join(map(re.escape, CLAIM_MEASURES)) + r")"
                   r"(?: among the (?P<group>" + "|".join(map(re.escape, RANKING_GROUPS)) + r"))?"
                   r"(?: on (?P<kinds>[^:]+?))?(?:: (?P<list>.+?))?\.?$")
# Words that state a ranking: outside a claim (and a generated block) they are an unchecked one.
RANKING_WORDS = re.compile(r"(?i)\b(?:wins?|winners?|most accurate|least accurate|cheapest|least work|most work|least time|"
                           r"most time|lowest error|highest error|largest error|smallest error|fastest|slowest|ahead of|"
                           r"behind|beats?|best|worst|the most|the least)\b|then `")
NOT_IN_TABLES = "not in this run's tables"


def kind_slug(heading):
    """A kind's heading as a marker and anchor: `contact shadows` → `contact-shadows`."""
    return re.sub(r"[^a-z0-9]+", "-", heading.lower()).strip("-")


def markdown_tables(text):
    """The Markdown tables of `text`, each a list of rows, each a dict from header cell to cell."""
    tables, header = [], None
    for line in text.splitlines():
        if not line.startswith("|"):
            header = None
            continue
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        if header is None:
            header = cells
            tables.append([])
        elif not all(re.fullmatch(r":?-+:?", cell) for cell in cells):
            tables[-1].append(dict(zip(header, cells)))
    return tables


def cell_number(cell):
    """A table cell as a number (`1,953,087`, `0.0137`); None for an empty or `-` cell."""
    cell = (cell or "").replace(",", "").strip()
    return None if cell in ("", "-") else float(cell)


def kind_rows(text):
    """The rows of one kind's tables (a `### <kind>` subsection of results.md's `## kinds`), by
    technique: `mae` and `noise` (the MAE cell and its `± truth`), `ms`, `q1` and `q3` (the `ms IQR`
    cell), `work` (texel reads plus invocations), `flip` and `flip_noise` (a `FLIP (shaded)` table and its
    `FLIP noise floor`); None where
    the tables lack it. Only the defaults' rows count."""
    rows = {}
    for table in markdown_tables(text):
        for cells in table:
            name = cells.get("technique", "").strip("`")
            if not name or cells.get("point", "defaults") != "defaults":
                continue
            row = rows.setdefault(name, {"technique": name, "mae": None, "noise": None, "ms": None, "q1": None, "q3": None,
                                         "work": None, "flip": None, "flip_noise": None})
            if "MAE (± truth)" in cells:
                value, _, noise = cells["MAE (± truth)"].partition("±")
                row["mae"], row["noise"] = cell_number(value), cell_number(noise)
            if "ms" in cells:
                row["ms"] = cell_number(cells["ms"])
            spread = re.fullmatch(r"([0-9.]+)\s*[–-]\s*([0-9.]+)", cells.get("ms IQR", ""))
            if spread:
                row["q1"], row["q3"] = float(spread.group(1)), float(spread.group(2))
            if cell_number(cells.get("texel reads")) is not None and cell_number(cells.get("invocations")) is not None:
                row["work"] = int(cell_number(cells["texel reads"]) + cell_number(cells["invocations"]))
            if "FLIP (shaded)" in cells:
                row["flip"] = cell_number(cells["FLIP (shaded)"])
            if "FLIP noise floor" in cells:
                row["flip_noise"] = cell_number(cells["FLIP noise floor"])
    return rows


def kind_tables(results_text):
    """{kind heading: {"rows": kind_rows, "frames": timed frames or None}} of the `## kinds`
    section of a results file's text, and the run that made it: (date, commit), or None."""
    section = next((s for s in part_sections(results_text) if s.startswith("## kinds\n")), "")
    made = re.search(r"^_Generated by `[^`]*` on .*, (\d{4}-\d\d-\d\d \d\d:\d\d UTC), commit (.+)\._$", section, re.MULTILINE)
    kinds = {}
    for part in re.split(r"(?m)^### ", section)[1:]:
        heading, _, body = part.partition("\n")
        frames = re.search(r"--frames (\d+)", body)
        kinds[heading.strip()] = {"rows": kind_rows(body), "frames": int(frames.group(1)) if frames else None}
    return kinds, (made.group(1), made.group(2)) if made else None


def tied(measure, a, b):
    """Whether rows `a` and `b` tie on `measure`: errors closer than the sum of their ground truth's
    noises; FLIP means closer than the sum of their noise floors (within FLIP_TOLERANCE of the lower
    where the tables give no floor); times whose interquartile ranges overlap
    (without ranges, only equal times); work only when equal (it is counted exactly)."""
    if measure == "error":
        return a["mae"] == b["mae"] or abs(a["mae"] - b["mae"]) < (a["noise"] or 0.0) + (b["noise"] or 0.0)
    if measure == "flip":
        if a.get("flip_noise") is not None and b.get("flip_noise") is not None:
            return a["flip"] == b["flip"] or abs(a["flip"] - b["flip"]) < a["flip_noise"] + b["flip_noise"]
        return abs(a["flip"] - b["flip"]) <= FLIP_TOLERANCE * min(a["flip"], b["flip"])
    if measure == "time":
        if None in (a["q1"], a["q3"], b["q1"], b["q3"]):
            return a["ms"] == b["ms"]
        return a["q1"] <= b["q3"] and b["q1"] <= a["q3"]
    return a["work"] == b["work"]


MEASURE_KEY = {"error": "mae", "flip": "flip", "work": "work", "time": "ms"}


def beats(measure, a, b, worst=False):
    """Whether row `a` ranks ahead of row `b` on `measure`: lower (higher with `worst`), and not tied."""
    key = MEASURE_KEY[measure]
    return (a[key] > b[key] if worst else a[key] < b[key]) and not tied(measure, a, b)


def measured(rows, measure, among=None):
    """The rows that have `measure`, of the techniques `among` (all when None)."""
    key = MEASURE_KEY["error" if measure == "front" else measure]
    return [r for r in rows.values() if r[key] is not None and (measure != "front" or r["work"] is not None)
            and (among is None or r["technique"] in among)]


def placed(rows, measure, among=None, worst=False):
    """[(place, row)] best first (worst first with `worst`): a row's place is one more than the
    number of rows that beat it, so tied rows can share one."""
    pool = measured(rows, measure, among)
    key = MEASURE_KEY[measure]
    places = [(1 + sum(beats(measure, other, row, worst) for other in pool), row) for row in pool]
    return sorted(places, key=lambda p: (p[0], -p[1][key] if worst else p[1][key], p[1]["technique"]))


def front(rows, among=None):
    """The front of error against work, least work first: the rows that no other row beats on
    error with no more work, nor ties on error with less work."""
    pool = measured(rows, "front", among)
    dominated = lambda row: any(
        other is not row and ((other["work"] <= row["work"] and beats("error", other, row))
                              or (other["work"] < row["work"] and not beats("error", row, other))) for other in pool)
    return sorted((row for row in pool if not dominated(row)), key=lambda row: (row["work"], row["mae"]))


def ranking_value(measure, row):
    """A row's value on `measure`, as the rankings print it."""
    if measure == "error":
        return f"{row['mae']:.4f}"
    if measure == "flip":
        return f"{row['flip']:.5f}"
    if measure == "work":
        return f"{row['work']:,}"
    spread = f" ({row['q1']:.2f}–{row['q3']:.2f})" if row["q1"] is not None else ""
    return f"{row['ms']:.2f} ms{spread}"


def ranking_text(rows, measure):
    """Every measured technique in its place: `1. `a` 0.0137; 2= `b` 0.0232, `c` 0.0236; ...`."""
    parts = []
    for place, members in itertools.groupby(placed(rows, measure), key=lambda p: p[0]):
        members = [row for _, row in members]
        mark = f"{place}=" if len(members) > 1 else f"{place}."
        parts.append(f"{mark} " + ", ".join(f"`{row['technique']}` {ranking_value(measure, row)}" for row in members))
    return "; ".join(parts)


def winners(rows, measure, among=None):
    """The techniques in first place on `measure` (` = ` between tied ones), or NOT_IN_TABLES."""
    first = [row["technique"] for place, row in placed(rows, measure, among) if place == 1]
    return " = ".join(f"`{name}`" for name in first) if first else NOT_IN_TABLES


def has_spread(kind):
    return any(row["q1"] is not None for row in kind["rows"].values())


def time_note(kind):
    """What the time ranking rests on, where the tables carry no interquartile range."""
    if has_spread(kind) or not measured(kind["rows"], "time"):
        return ""
    frames = kind["frames"]
    timed = f", which timed {frames} frame{'s' if frames != 1 else ''} per technique" if frames else ""
    return f" (no interquartile ranges in this run's tables{timed}: ordered by those times, no tie decidable)"


def rankings_how():
    """docs/choosing.md's `rankings:how` block: what each ranking is and how ties are decided."""
    groups = "; ".join(f"the {name}{RANKING_GROUP_NOTES.get(name, '')}: {', '.join(f'`{t}`' for t in members)}" for name, members in RANKING_GROUPS.items())
    return (f"_Generated by `{RANKINGS_COMMAND}` (which `scripts/results.sh` runs): do not edit, rerun it._\n\n"
            "- **Error**, lowest first: the mean absolute visibility error over the pixels that the ground truth or the "
            "technique shadows (the tables' `MAE`); two errors closer than the sum of their ground truth's own errors "
            "(the `± truth` beside each) are tied.\n"
            f"- **FLIP**, lowest first: the mean FLIP of the shaded image against the shaded ground truth; two FLIP means "
            f"closer than the sum of their noise floors are tied (the floor: the larger FLIP of the truth's shaded image against "
            f"the same shading of its visibility moved down or up by its own noise, the tables' `FLIP noise floor`); in "
            f"tables without a floor, two within {FLIP_TOLERANCE:.0%} of the lower, a stand-in.\n"
            "- **Work**, least first: texel reads plus shader invocations per frame (the tables' `texel reads` and "
            "`invocations`), counted exactly, so tied only when equal.\n"
            "- **Time**, least first: the median time per frame (lavapipe's, on a CPU); two times are tied when the "
            "interquartile ranges of their timed frames overlap, and never where the tables give no range.\n"
            "- **Error against work**, least work first: the front, the techniques that no other beats on error with "
            "no more work, nor ties on error with less: for each, nothing that costs less work is as accurate.\n"
            "- A technique's place is one more than the number of techniques that beat it (better, and not tied), "
            "so tied techniques can share a place (`3=`).\n"
            f"- The groups a claim below may rank within: {groups}.\n")


def kind_block(heading, kind, made):
    """docs/choosing.md's generated block for one kind of scene."""
    slug = kind_slug(heading)
    rows = kind["rows"]
    run = f", the run of {made[0]}, commit {made[1]}" if made else ""
    line = lambda label, measure: f"- {label}: {ranking_text(rows, measure) if measured(rows, measure) else NOT_IN_TABLES}."
    on_front = front(rows)
    front_text = ", ".join(f"`{r['technique']}` ({r['work']:,}; {r['mae']:.4f})" for r in on_front) if on_front else NOT_IN_TABLES
    return "\n".join([
        f"_Generated by `{RANKINGS_COMMAND}` from the table of [results.md#{slug}](results.md#{slug}){run}: do not edit, rerun it._",
        "",
        line("Error, lowest first", "error"),
        line("FLIP of the shaded image, lowest first", "flip"),
        line("Work (texel reads and invocations per frame), least first", "work"),
        line("Time, least first", "time")[:-1] + time_note(kind) + ".",
        f"- Error against work, the front, least work first (work; error): {front_text}.",
    ]) + "\n"


def leaders(section):
    """The line under a kind's table in docs/results.md: the first places, from the same
    rankings as docs/choosing.md (`section`: the kind's subsection, its tables)."""
    kind = {"rows": kind_rows(section), "frames": None}
    rows = kind["rows"]
    return (f"Lowest error: {winners(rows, 'error')}; least counted work (texel reads and invocations): {winners(rows, 'work')}; "
            f"least time: {winners(rows, 'time')}{time_note(kind)}. Ties, the full orders and the front of error against work: "
            "[choosing.md](choosing.md).")


def readme_rankings(kinds):
    """The rankings under the README's summary table: each kind's first places and front."""
    any_flip = any(measured(kind["rows"], "flip") for kind in kinds.values())
    columns = ["lowest error", *(["lowest FLIP"] if any_flip else []), "least work", "least time"]
    measures = ["error", *(["flip"] if any_flip else []), "work", "time"]
    lines = ["Each kind of scene's first places, from the tables of [docs/results.md](docs/results.md#kinds) "
             "(`=`: tied; the full orders, and how ties are decided: [docs/choosing.md](docs/choosing.md)):", "",
             "| kind of scene | " + " | ".join(columns) + " | front of error against work, least work first |",
             "|---|" + "---|" * (len(columns) + 1)]
    for heading, *_ in SCENE_KINDS:
        kind = kinds.get(heading)
        if kind is None:
            cells = [NOT_IN_TABLES] * (len(columns) + 1)
        else:
            cells = [winners(kind["rows"], m) for m in measures]
            cells.append(", ".join(f"`{row['technique']}`" for row in front(kind["rows"])) or NOT_IN_TABLES)
        lines.append(f"| {heading} | " + " | ".join(cells) + " |")
    notes = []
    if not any_flip:
        notes.append(f"FLIP of the shaded image: {NOT_IN_TABLES}.")
    if kinds and not any(has_spread(kind) for kind in kinds.values()):
        notes.append("Times: no interquartile ranges in this run's tables: ordered by their medians, no tie decidable.")
    return "\n".join(lines) + "\n" + (f"\n{' '.join(notes)}\n" if notes else "")


def summary_words(text):
    """A docs/summary.toml entry's words as the tables print them: claims lose their braces."""
    return re.sub(r"\{([^{}]*)\}", r"\1", text)


def summary_entries():
    if not SUMMARY_WORDS.exists():
        return {}
    return {entry["name"]: entry for entry in tomllib.loads(SUMMARY_WORDS.read_text()).get("technique", [])}


def with_current_words(summary):
    """`summary` (docs/results/summary.md, the last run's) with its words columns as docs/summary.toml has them now."""
    entries, lines = summary_entries(), []
    for line in summary.splitlines():
        name = re.match(r"^\| (?:\[`([a-z0-9-]+)`\]\([^)]*\)|`([a-z0-9-]+)`) \|", line)
        entry = entries.get((name.group(1) or name.group(2)) if name else None)
        if entry:
            cells = line[2:-2].split(" | ")
            cells[1:4] = [summary_words(entry.get(key, "")) for key in ("best", "worst", "cost")]
            line = "| " + " | ".join(cells) + " |"
        lines.append(line)
    return "\n".join(lines) + "\n"


def readme_summary(results_text):
    """What goes between README.md's summary markers: the last run's summary table (its words as
    docs/summary.toml has them now), then the rankings of each kind of scene."""
    kinds, _ = kind_tables(results_text)
    summary = with_current_words((ROOT / "docs" / "results" / "summary.md").read_text())
    return f"{summary}\n{readme_rankings(kinds)}"


def blocks(text):
    """{name: inner text} of the `<!-- rankings:<name> -->` … `<!-- /rankings:<name> -->` blocks of `text`."""
    return {m.group(1): m.group(2) for m in re.finditer(r"(?ms)^<!-- rankings:([a-z0-9-]+) -->\n(.*?)^<!-- /rankings:\1 -->$", text)}


def expected_blocks(results_text):
    kinds, made = kind_tables(results_text)
    expected = {"how": rankings_how()}
    for heading, *_ in SCENE_KINDS:
        kind = kinds.get(heading, {"rows": {}, "frames": None})
        expected[kind_slug(heading)] = kind_block(heading, kind, made)
    return expected


def with_blocks(text, expected):
    """`text` with each of its rankings blocks replaced by `expected`'s (names without one are kept)."""
    return re.sub(r"(?ms)^(<!-- rankings:([a-z0-9-]+) -->\n)(.*?)(^<!-- /rankings:\2 -->)$",
                  lambda m: m.group(1) + expected.get(m.group(2), m.group(3)) + m.group(4), text)


def write_rankings(results_text):
    """Rewrites docs/choosing.md's rankings blocks and README.md's summary block from `results_text`."""
    expected = expected_blocks(results_text)
    text = CHOOSING.read_text()
    missing = sorted(set(expected) - set(blocks(text)))
    if missing:
        print(f"results: docs/choosing.md has no rankings block for {', '.join(missing)} "
              f"(add `<!-- rankings:<name> -->` and `<!-- /rankings:<name> -->` lines)", file=sys.stderr)
    updated = with_blocks(text, expected)
    if updated != text:
        CHOOSING.write_text(updated)
        print("results: wrote docs/choosing.md's rankings", file=sys.stderr)
    splice_summary(readme_summary(results_text))


def parsed_claim(text, where):
    """A claim's parts ({measure, worst, group, kinds, steps}) or a problem (a string)."""
    match = CLAIM.match(text.strip())
    if not match:
        return f"{where}: `{text}` is not a claim this checker reads (see the rankings block `how`)"
    measure, worst = CLAIM_MEASURES[match.group("measure").lower()]
    kinds = None
    if match.group("kinds"):
        named = match.group("kinds").strip()
        headings = [h for h, *_ in SCENE_KINDS]
        kinds = headings if named == "every kind" else [k.strip() for k in re.split(r",\s*(?:and\s+)?|\s+and\s+", named)]
        unknown = [k for k in kinds if k not in headings]
        if unknown:
            return f"{where}: `{text}` names no kind of scene {unknown} (the kinds: {', '.join(headings)}; or `every kind`)"
    steps = []
    for step in re.split(r"[,;]?\s+then\s+", match.group("list") or ""):
        if not step.strip():
            continue
        names = re.findall(r"`([^`]+)`", step)
        if not names or set(re.sub(r"`[^`]+`", " ", step).replace(",", " ").split()) - {"and"}:
            return f"{where}: `{text}`: each step of a ranking is technique names (`a`, `b` and `c`) between `then`s"
        steps.append(names)
    return {"text": text, "measure": measure, "worst": worst, "group": match.group("group"), "kinds": kinds, "steps": steps}


def claim_problems(claim, kinds, where):
    """Where the tables contradict `claim`: each step's techniques are ranked, on every kind named,
    behind none of the techniques not named before them (within the claim's group); a front claim's
    techniques are on the front."""
    problems = []
    among = RANKING_GROUPS[claim["group"].lower()] if claim["group"] else None
    for heading in claim["kinds"] or []:
        rows = kinds.get(heading, {}).get("rows", {})
        pool = measured(rows, claim["measure"], among)
        if not pool:
            problems.append(f"{where}: `{claim['text']}`: {claim['measure']} on {heading} is {NOT_IN_TABLES}")
            continue
        names = {row["technique"] for row in pool}
        if claim["measure"] == "front":
            on = [row["technique"] for row in front(rows, among)]
            for name in (n for step in claim["steps"] for n in step if n not in on):
                problems.append(f"{where}: `{claim['text']}`: on {heading}, `{name}` is not on the front ({', '.join(on)})")
            continue
        before = set()
        for step in claim["steps"]:
            for name in step:
                if name not in names:
                    problems.append(f"{where}: `{claim['text']}`: `{name}` has no {claim['measure']} on {heading}"
                                    + (f" among the {claim['group']}" if among else ""))
                    continue
                ahead = [other for other in pool if other["technique"] not in before and other["technique"] != name
                         and beats(claim["measure"], other, rows[name], claim["worst"])]
                if ahead:
                    values = ", ".join(f"`{o['technique']}` {ranking_value(claim['measure'], o)}" for o in ahead)
                    problems.append(f"{where}: `{claim['text']}`: on {heading}, `{name}` "
                                    f"({ranking_value(claim['measure'], rows[name])}) is ranked after {values}")
            before |= set(step)
    return problems


def choosing_problems(text, kinds):
    """docs/choosing.md's hand-written claims that the tables contradict, and its unchecked ranking words."""
    problems = []
    # The generated blocks and the ``double-backtick`` code spans (examples) out, their line breaks
    # kept so that line numbers hold.
    blank = lambda m: re.sub(r"[^\n]", " ", m.group(0))
    hand = re.sub(r"(?ms)^<!-- rankings:([a-z0-9-]+) -->\n.*?^<!-- /rankings:\1 -->$", blank, text)
    hand = re.sub(r"(?s)``.*?``", blank, hand)
    headings = {h: h for h, *_ in SCENE_KINDS}
    kind_at = lambda at: next((headings.get(m.group(1).strip().lower()) for m in reversed(list(re.finditer(r"(?m)^## (.*)$", hand[:at])))), None)
    read = lambda bold: CLAIM.match(bold) or RANKING_WORDS.search(bold)
    claims = 0
    # A claim is a bold span, which may run over a line break.
    for bold in re.finditer(r"(?s)\*\*(.+?)\*\*", hand):
        words = " ".join(bold.group(1).split())
        if not read(words):
            continue
        where = f"docs/choosing.md:{hand.count(chr(10), 0, bold.start()) + 1}"
        claim = parsed_claim(words, where)
        if isinstance(claim, str):
            problems.append(claim)
            continue
        if not claim["steps"]:
            problems.append(f"{where}: `{claim['text']}` names no technique")
            continue
        if claim["kinds"] is None:
            kind = kind_at(bold.start())
            if kind is None:
                problems.append(f"{where}: `{claim['text']}` is under no kind's heading: name the kinds (`... on thin geometry: ...`)")
                continue
            claim["kinds"] = [kind]
        claims += 1
        problems += claim_problems(claim, kinds, where)
    # The rest (claims, and bold already reported, blanked; link targets dropped) states no ranking.
    rest = re.sub(r"(?s)\*\*(.+?)\*\*", lambda m: blank(m) if read(" ".join(m.group(1).split())) else m.group(0), hand)
    for line_number, line in enumerate(rest.splitlines(), 1):
        line = re.sub(r"\]\([^)]*\)", "]", line)
        problems += [f"docs/choosing.md:{line_number}: `{word.group(0)}` states a ranking outside a checked claim: {text.splitlines()[line_number - 1].strip()}"
                     for word in RANKING_WORDS.finditer(line)]
    if claims == 0:
        problems.append("docs/choosing.md: no claims found (`**Lowest error: `wedges`**`)")
    return problems


def summary_problems(kinds, entries=None):
    """docs/summary.toml's claims (`{most accurate on thin geometry}` in a technique's words) that the
    tables contradict, and its ranking words outside claims (`entries`: docs/summary.toml's by default)."""
    problems = []
    for name, entry in (summary_entries() if entries is None else entries).items():
        for key in ("best", "worst"):
            text = entry.get(key, "")
            where = f"docs/summary.toml ({name}, {key})"
            for braced in re.findall(r"\{([^{}]*)\}", text):
                claim = parsed_claim(braced, where)
                if isinstance(claim, str):
                    problems.append(claim)
                    continue
                if claim["steps"] or claim["kinds"] is None:
                    problems.append(f"{where}: `{braced}`: a summary claim names the kinds of scene and no technique "
                                    "(`{most accurate on thin geometry}`: the entry's technique is the one ranked)")
                    continue
                claim["steps"] = [[name]]
                problems += claim_problems(claim, kinds, where)
            for word in RANKING_WORDS.finditer(re.sub(r"\{[^{}]*\}", " ", text)):
                problems.append(f"{where}: `{word.group(0)}` states a ranking outside a checked claim `{{...}}`: {text}")
    return problems


def rankings_problems(results_text, parts):
    """Every disagreement between the rankings `results_text` gives and the files that carry them:
    `blocks` (docs/choosing.md's generated blocks and README.md's summary block), `claims`
    (docs/choosing.md's hand-written claims), `summary` (docs/summary.toml's)."""
    kinds, _ = kind_tables(results_text)
    problems = []
    missing = [h for h, *_ in SCENE_KINDS if not kinds.get(h, {}).get("rows")]
    if missing:
        problems.append(f"docs/results.md: no `## kinds` table for {', '.join(missing)}")
    choosing = CHOOSING.read_text()
    if "blocks" in parts:
        found = blocks(choosing)
        for name, inner in expected_blocks(results_text).items():
            if name not in found:
                problems.append(f"docs/choosing.md: no `<!-- rankings:{name} -->` … `<!-- /rankings:{name} -->` block")
            elif found[name] != inner:
                diff = "\n".join(difflib.unified_diff(found[name].splitlines(), inner.splitlines(), "docs/choosing.md", "derived", lineterm="", n=0))
                problems.append(f"docs/choosing.md: the rankings block `{name}` is not what {RANKINGS_COMMAND} derives:\n{diff}")
        readme = (ROOT / "README.md").read_text()
        if SUMMARY_BEGIN in readme and SUMMARY_END in readme:
            current = readme.split(SUMMARY_BEGIN, 1)[1].split(SUMMARY_END, 1)[0]
            derived = "\n" + readme_links(readme_summary(results_text))
            if current != derived:
                diff = "\n".join(difflib.unified_diff(current.splitlines(), derived.splitlines(), "README.md", "derived", lineterm="", n=0))
                problems.append(f"README.md: the summary block is not what {RANKINGS_COMMAND} derives:\n{diff}")
    if "claims" in parts:
        problems += choosing_problems(choosing, kinds)
    if "summary" in parts:
        problems += summary_problems(kinds)
    return problems


def part_sections(text):
    """`text` cut into the parts' sections, each from its `## <part>` heading to the next: only the
    parts' own headings open one (a report's own `## ` headings, and each part's `### `
    subsections, stay inside)."""
    names = "|".join(re.escape(n) for n in ["summary", "defaults", "trade", "lights", "kinds", *TECHNIQUES])
    parts = re.split(rf"(?m)^(?=## (?:{names})\n)", text)
    return [p.rstrip("\n") + "\n" for p in parts if p.startswith("## ")]


def merged_sections(previous, fresh):
    """The part sections of `previous` (a results file) in their order, each replaced by the section
    of `fresh` (part sections) with the same heading, and `fresh`'s new parts after them: what a
    partial run writes, keeping the parts it did not run."""
    heading = lambda section: section.split("\n", 1)[0]
    replacement = {heading(section): section for section in fresh}
    merged = [replacement.pop(heading(section), section) for section in part_sections(previous)]
    return merged + [section for section in fresh if heading(section) in replacement]


def readme_links(summary):
    """`summary`'s links (relative to docs/results/) made relative to the workspace's root."""
    return summary.replace("](../../", "](").replace("](../results.md)", "](docs/results.md)")


def splice_summary(summary):
    """Puts `summary` (docs/results/summary.md, links relative to docs/results/) between README.md's
    summary markers, its links made relative to the workspace's root (nothing happens without them)."""
    summary = readme_links(summary)
    readme = ROOT / "README.md"
    text = readme.read_text()
    if SUMMARY_BEGIN in text and SUMMARY_END in text:
        head, rest = text.split(SUMMARY_BEGIN, 1)
        _, tail = rest.split(SUMMARY_END, 1)
        readme.write_text(f"{head}{SUMMARY_BEGIN}\n{summary}{SUMMARY_END}{tail}")
    else:
        print("results: README.md has no summary markers; the summary table is in docs/results/summary.md", file=sys.stderr)


def without_params(report):
    """`report` with the params column of its tables removed (every technique is at its defaults)."""
    lines, dropping = [], False
    for line in report.splitlines():
        if line.startswith("| technique | params |"):
            dropping = True
        elif not line.startswith("|"):
            dropping = False
        if dropping:
            cells = line.split("|")
            line = "|".join(cells[:2] + cells[3:])
        lines.append(line)
    return "\n".join(lines)


def summary_table(rows, args, prefix=""):
    """One row per technique: docs/summary.toml's words, then the penumbra error on each summary scene,
    the time and the texel reads per frame on the first; links relative to the workspace's root,
    behind `prefix` (`../` from docs/)."""
    words = {}
    summary_file = ROOT / "docs" / "summary.toml"
    if summary_file.exists():
        for entry in tomllib.loads(summary_file.read_text()).get("technique", []):
            words[entry["name"]] = entry
    scenes = SUMMARY_SCENES
    head = ("| technique | best at | worst at | cost class | " + " | ".join(f"MAE `{s}`" for s in scenes)
            + f" | ms `{scenes[0]}` (IQR) | texel reads `{scenes[0]}` |\n|---|---|---|---|" + "---:|" * (len(scenes) + 2) + "\n")
    order = [entry for entry in words] + sorted(name for name in rows if name not in words)
    lines = []
    for name in order:
        if name not in rows:
            continue
        entry = words.get(name, {})
        first = rows[name].get(scenes[0], {})
        cells = [f"[`{name}`]({prefix}ssm-techniques/{name}/README.md)" if (ROOT / "ssm-techniques" / name).is_dir() else f"`{name}`",
                 *(summary_words(entry.get(key, "")) for key in ("best", "worst", "cost"))]
        cells += [error_cell(rows[name].get(s, {})) for s in scenes]
        cells.append(time_cell(first))
        cells.append(first.get("texel_reads", "") and f"{int(float(first['texel_reads'])):,}")
        lines.append("| " + " | ".join(cells) + " |")
    return head + "\n".join(lines) + (f"\n\nMAE: mean absolute error of the visibility over the pixels that the ground truth or the technique "
                                      f"shadows, ± the ground truth's own error over the same pixels; {args.width}×{args.height} pixels.\n")


def flip_table(rows):
    """The FLIP of each row's shaded image against the shaded ground truth (`flip_mean` of sweep.csv's
    `rows`), a table under a kind's sweep table (sweep.md has no FLIP column); empty without it."""
    rows = [row for row in rows if row.get("flip_mean") not in (None, "")]
    if not rows:
        return ""
    floor = lambda row: f"{float(row['flip_noise']):.5f}" if row.get("flip_noise") not in (None, "") else "-"
    lines = [f"| {row['technique']} | {float(row['flip_mean']):.5f} | {floor(row)} |" for row in rows]
    return "FLIP of the shaded image against the shaded ground truth (sweep.csv's `flip_mean`, and `flip_noise`: what the truth's own noise alone shows):\n\n" \
           "| technique | FLIP (shaded) | FLIP noise floor |\n|---|---:|---:|\n" + "\n".join(lines)


def time_cell(row):
    """A row's median GPU time with its interquartile range across the timed frames; empty when not timed."""
    if row.get("gpu_ms_median") in (None, ""):
        return ""
    spread = f" ({float(row['gpu_ms_q1']):.2f}–{float(row['gpu_ms_q3']):.2f})" if row.get("gpu_ms_q1") not in (None, "") else ""
    return f"{float(row['gpu_ms_median']):.2f}{spread}"


def error_cell(row):
    """A row's headline error with the ground truth's noise beside it; empty when not measured."""
    if row.get("mae") in (None, ""):
        return ""
    noise = row.get("truth_noise")
    return f"{float(row['mae']):.4f}" + (f" ± {float(noise):.4f}" if noise not in (None, "") else "")


if __name__ == "__main__":
    main()
