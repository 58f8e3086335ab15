#!/usr/bin/env python3
"""Regenerates every results table and figure of the docs and of each technique's README.

Run through scripts/results.sh (see its header for the options). On lavapipe it writes
docs/results.md, docs/results/*.svg, ssm-techniques/<t>/results.md (+ results/*.svg) and the summary
table of README.md; on any other adapter one file, docs/results-<adapter>.md (+ docs/results/<adapter>/),
so that a GPU run lands beside the lavapipe one. Every generated file's first lines name the
command, the adapter, the date and the commit. Nothing here measures anything itself: each table
is the output of an `ssm` command (or a crate's example), copied as it printed it.
"""

import argparse
import csv
import datetime
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
    "wedges": [("ssm-wedges", "wedges_work", []), ("ssm-wedges", "fig1", []), ("ssm-wedges", "fig12", [])],
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
    """(name, technique or None, description) of every sweep preset, as `ssm sweep --list-presets` prints them."""
    listing = subprocess.run([str(SSM), "sweep", "--list-presets"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    found = []
    for line in listing.splitlines():
        match = re.match(r"^([a-z0-9-]+)(?: \[([a-z0-9-]+)\])?: (.*)$", line)
        if match:
            found.append((match.group(1), match.group(2), match.group(3)))
    return found


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
    parser.add_argument("--output-root", type=Path, default=ROOT, help="write the generated files under this folder, laid out as the workspace (default: the workspace itself; elsewhere README.md is left alone)")
    parser.add_argument("--splice-summary", action="store_true", help="only copy docs/results/summary.md (written by the last full run) into README.md")
    parser.add_argument("--only", default="", help="comma-separated parts to run: summary, trade, lights, kinds, and technique names (default: all)")
    args = parser.parse_args(sys.argv[1:])
    only = set(filter(None, args.only.split(",")))
    if args.splice_summary:
        splice_summary((ROOT / "docs" / "results" / "summary.md").read_text())
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
                    "draws its advice from these tables). Under each table: the lowest error, the least counted work "
                    "(texel reads and invocations) and the least time of the run.\n")
        for heading, scene, extra, what in SCENE_KINDS:
            out = scratch / f"kind-{re.sub(r'[^a-z0-9]+', '-', heading)}"
            command = [str(SSM), "sweep", "--scene", scene, *extra, *[a for t in TECHNIQUES for a in ("--vary", t)], *size_args,
                       "--frames", str(args.frames), "--count-work", "--out", str(out)]
            run(command, log, env=env)
            rows = list(csv.DictReader(open(out / "sweep.csv")))
            body.append(f"### {heading}\n\n{what}.\n\n`{shown(command, scratch)}`\n\n{sweep_table(out)}\n\n{leaders(rows)}\n")

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
            splice_summary(summary)
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

    # 6. Each technique's paper presets and the examples that reproduce its cost claims, the
    # technique's results written as soon as they are done.
    by_technique = {}
    for name, technique, description in presets():
        if technique is not None and wanted(technique):
            by_technique.setdefault(technique, []).append((name, description))
    for technique in EXAMPLES:
        if wanted(technique):
            by_technique.setdefault(technique, [])
    # Cheaper techniques first, so that a run stopped part-way has the most to show.
    order = ["hard", "pcss", "multi-sm", "vssm", "sssm", "wedges", "atty", "pvsm"]
    for technique, technique_presets in sorted(by_technique.items(), key=lambda item: order.index(item[0]) if item[0] in order else len(order)):
        sections = []
        for name, description in technique_presets:
            out = scratch / f"preset-{name}"
            command = [str(SSM), "sweep", "--preset", name, *size_args, "--frames", str(args.frames), "--count-work", "--out", str(out)]
            run(command, log, env=env)
            sections.append((name, description, command, out))
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


def leaders(rows):
    """One line naming, among `rows` (a sweep.csv's), the lowest error, the least work and the least time."""
    def best(key, unit):
        scored = [(float(r[key]), r["technique"]) for r in rows if r.get(key) not in (None, "")]
        if not scored:
            return "not measured"
        value, name = min(scored)
        return f"`{name}` ({value:,.0f}{unit})" if value >= 1000 else f"`{name}` ({value:.4g}{unit})"
    for row in rows:
        counts = [row.get(k) for k in ("vertex_invocations", "fragment_invocations", "compute_invocations", "texel_reads")]
        row["work"] = str(sum(float(c) for c in counts)) if all(c not in (None, "") for c in counts) else ""
    return (f"Lowest error: {lowest_error(rows)}; least counted work: {best('work', ' reads and invocations')}; "
            f"least time: {best('gpu_ms_median', ' ms')}.")


def lowest_error(rows):
    """The technique with the lowest headline error among `rows`, and those tied with it: errors closer
    than the ground truth's combined noise over their pixels (`truth_noise` of each) are a tie."""
    scored = [(float(r["mae"]), float(r.get("truth_noise") or 0.0), r["technique"]) for r in rows if r.get("mae") not in (None, "")]
    if not scored:
        return "not measured"
    value, noise, name = min(scored)
    tied = [f"`{n}` ({v:.4g})" for v, m, n in sorted(scored) if n != name and abs(v - value) < noise + m]
    text = f"`{name}` ({value:.4g} ± {noise:.2g})"
    return text + (f", tied within the truth's noise with {', '.join(tied)}" if tied else "")


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


def splice_summary(summary):
    """Puts `summary` (docs/results/summary.md, links relative to docs/results/) between README.md's
    summary markers, its links made relative to the workspace's root (nothing happens without them)."""
    summary = summary.replace("](../../", "](").replace("](../results.md)", "](docs/results.md)")
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
                 entry.get("best", ""), entry.get("worst", ""), entry.get("cost", "")]
        cells += [error_cell(rows[name].get(s, {})) for s in scenes]
        cells.append(time_cell(first))
        cells.append(first.get("texel_reads", "") and f"{int(float(first['texel_reads'])):,}")
        lines.append("| " + " | ".join(cells) + " |")
    return head + "\n".join(lines) + (f"\n\nMAE: mean absolute error of the visibility over the pixels that the ground truth or the technique "
                                      f"shadows, ± the ground truth's own error over the same pixels; {args.width}×{args.height} pixels.\n")


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
