#!/usr/bin/env bash
# Where a technique's GPU time goes on lavapipe, by JIT-compiled function: renders with `ssm
# render` for long enough to sample it with perf, copies the JIT code out of the process (gdb) and
# attributes the samples to the functions llvmpipe compiled: the pipelines' shader bodies and the
# texel-fetch functions they call (those with a gather). Prints, per function, its share of the
# samples, its instruction count and its gathers, divisions and calls (the first PROFILE_ROWS,
# default 16; with PROFILE_GROUP=1 the copies of a function with the same instructions are one
# row, and `copies` counts them). PROFILE_WIDTH and PROFILE_HEIGHT set the image (640×480).
#
#   scripts/lavapipe-profile.sh [ssm render arguments...]
#   scripts/lavapipe-profile.sh --scene leaves --technique sssm --set sssm.blocker_kernel=29 \
#       --set sssm.blur_kernel=41 --set sssm.alpha=0.1 --set sssm.beta=0.1
#
# Needs: a release build of `ssm` (target/release/ssm), perf, gdb, objdump, python3; one
# technique per run (its passes are the hot functions; a shader's texel fetches lie just before
# it in the same mapping). Run on lavapipe only: a GPU's time is not
# on the CPU.
set -euo pipefail
cd "$(dirname "$0")/.."
for tool in perf gdb objdump python3; do
    command -v "$tool" >/dev/null || { echo "lavapipe-profile: '$tool' is missing" >&2; exit 1; }
done
ssm=target/release/ssm
[ -x "$ssm" ] || { echo "lavapipe-profile: build it first: cargo build --release -p ssm-bench --bin ssm" >&2; exit 1; }
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
work=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; rm -rf "$work"' EXIT
# Enough frames to outlast the start-up and the sampling window.
"$ssm" render --frames "${PROFILE_FRAMES:-150}" --width "${PROFILE_WIDTH:-640}" --height "${PROFILE_HEIGHT:-480}" "$@" --out "$work/out" >/dev/null 2>&1 &
pid=$!
sleep "${PROFILE_WARMUP_S:-8}"
kill -0 "$pid" 2>/dev/null || { echo "lavapipe-profile: the render ended before sampling (raise PROFILE_FRAMES)" >&2; exit 1; }
perf record -e cpu-clock -F 4000 -p "$pid" -o "$work/perf.data" -- sleep "${PROFILE_SAMPLE_S:-4}" >/dev/null 2>&1
cat "/proc/$pid/maps" >"$work/maps"
perf report -i "$work/perf.data" --sort sym --stdio 2>/dev/null | grep -v '^#' | grep -v '^$' >"$work/samples" || true
python3 - "$pid" "$work" <<'PY'
import bisect, collections, glob, os, re, subprocess, sys
pid, work = sys.argv[1], sys.argv[2]
executable = []
for line in open(f'{work}/maps'):
    fields = line.split()
    start, end = (int(x, 16) for x in fields[0].split('-'))
    # JIT code: executable anonymous mappings.
    if 'x' in fields[1] and len(fields) < 6:
        executable.append((start, end))
samples = collections.Counter()
for line in open(f'{work}/samples'):
    fields = line.split()
    if len(fields) >= 3 and fields[2].startswith('0x'):
        samples[int(fields[2], 16)] += float(fields[0].rstrip('%'))
regions = {(s, e) for a in samples for s, e in executable if s <= a < e}
commands = []
for s, e in sorted(regions):
    commands += ['-ex', f'dump binary memory {work}/jit-{s:x}.bin {s:#x} {e:#x}']
subprocess.run(['gdb', '-p', pid, '-batch'] + commands, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
instructions = []
for path in glob.glob(f'{work}/jit-*.bin'):
    start = path.rsplit('-', 1)[1][:-4]
    listing = subprocess.run(['objdump', '-D', '-b', 'binary', '-mi386:x86-64', f'--adjust-vma=0x{start}', path],
                             capture_output=True, text=True, check=True).stdout
    for line in listing.splitlines():
        m = re.match(r'\s*([0-9a-f]+):\s+(?:[0-9a-f]{2} )+\s*(\S.*)', line)
        if m:
            instructions.append((int(m.group(1), 16), m.group(2).strip()))
instructions.sort()
# A function starts at the first instruction after a return that is not padding.
starts, after_return = [], True
for address, text in instructions:
    if after_return and not re.match(r'(nop|int3|xchg %ax,%ax|data16|cs nop)', text):
        starts.append(address)
        after_return = False
    if text.startswith('ret'):
        after_return = True
shares = collections.Counter()
for address, share in samples.items():
    i = bisect.bisect_right(starts, address) - 1
    if i >= 0 and any(s <= address < e for s, e in regions):
        shares[starts[i]] += share
addresses = [a for a, _ in instructions]
# llvmpipe may compile a function again for another pipeline state or shader (one texel fetch
# serves several passes): with PROFILE_GROUP=1, copies with the same instructions, addresses
# aside, are one row.
group_copies = os.environ.get('PROFILE_GROUP') == '1'
groups = {}
for start, share in shares.items():
    i = bisect.bisect_left(addresses, start)
    body = []
    while i < len(instructions):
        body.append(instructions[i][1])
        if instructions[i][1].startswith('ret'):
            break
        i += 1
    key = tuple(re.sub(r'0x[0-9a-f]+', '', t) for t in body) if group_copies else start
    group = groups.setdefault(key, {'share': 0.0, 'copies': 0, 'start': start, 'body': body})
    group['share'] += share
    group['copies'] += 1
print(f'JIT code: {sum(shares.values()):.1f}% of the samples, {sum(samples.values()):.1f}% attributed in all')
print('share  copies  instructions  gathers  divisions  calls  function')
for group in sorted(groups.values(), key=lambda g: -g['share'])[:int(os.environ.get('PROFILE_ROWS', '16'))]:
    body = group['body']
    ops = collections.Counter(t.split()[0] for t in body)
    gathers = ops['vpgatherdd'] + ops['vgatherdps']
    # llvmpipe compiles each texture read as a small function called from the shader: one
    # gather for a one-channel texel, per-lane loads for a four-channel one.
    kind = 'shader' if len(body) >= 400 else 'texel fetch, gather' if gathers else 'texel fetch, per-lane loads'
    print(f'{group["share"]:5.1f}%  {group["copies"]:6d}  {len(body):12d}  {gathers:7d}  {ops["vdivps"]:9d}  {ops["call"]:5d}  {kind} at {group["start"]:#x}')
PY
