"""Bandwidth: the machine's memory and L1 bandwidth, and a roofline for the stencil kernel.

What it measures
----------------
1. Machine: the CPU model (/proc/cpuinfo) and cpu0's caches
   (/sys/devices/system/cpu/cpu0/cache/index*/{level,type,size,shared_cpu_list}).
2. A STREAM-like triad a[i] = b[i] + s * c[i] in a Numba njit(parallel=True) loop on 1 and on
   2 threads (--threads), for three arrays of each size in --sizes (bytes per array; the
   arrays are split evenly among the threads, each thread its own contiguous part, first
   touched by that thread). Cache-resident sizes are repeated inside one parallel region
   (reps passes, enough for about --min-bytes of traffic per timed call, so fork/join costs
   nothing); arrays beyond the last-level cache make one pass per timed call. Best of
   --repeats timed calls. Bandwidth counts 24 B per element and pass (read b, read c, write a)
   as STREAM does; with write-allocate the bus also reads a, so real traffic out of memory is
   4/3 of that. Default sizes: 8 kB (L1), 256 kB (L2), 80 MB, and "llc" = 4/3 of the
   last-level cache rounded up to a MB (three arrays = 4x the LLC; at least 80 MB), which is
   the memory bandwidth used below.
3. The central-difference kernel of benchmarks/stencil.py (`kernel_run`, imported from it):
   --spans spans of --intervals intervals, --transits transits, on each thread count, best
   of --repeats; and stencil.py's NumPy version (`numpy_run`, the whole grid advanced one
   array update per level) on --numpy-spans spans (several, comma-separated; "llc" = enough
   spans for its three level arrays to be twice the last-level cache), about --numpy-updates
   point-updates per run (at least 5 levels), best of min(--repeats, 3). NumPy's temporaries
   add about five more level arrays: with "llc" it needs about 5x the LLC of memory.
4. Roofline: a point-update that streamed from memory would read u_cur and u_prev and write
   u_next, 24 B (the triad's accounting), so the memory-bound limit is
   bandwidth(beyond LLC, same threads) / 24 B point-updates/s. The script prints that limit
   next to the measured rates, and one paragraph saying where the kernel and NumPy stand.

Command (run on an otherwise idle machine; with the defaults it needs about 5x the LLC of
memory, e.g. 2.7 GB for a 480 MiB LLC)
------------------------------------------------------------------------------------------
    PYTHONPATH=. python benchmarks/bandwidth.py --json bandwidth.json

Small check: PYTHONPATH=. python benchmarks/bandwidth.py --sizes 8k,256k,80M --spans 50 \\
    --numpy-spans 200 --numpy-updates 2e7 --repeats 2
Prints Markdown tables to stdout; --json PATH also writes every number as JSON.
"""

from __future__ import annotations

import argparse
import math
import platform
import sys
import time
from pathlib import Path

import numba as nb
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels

from bench_common import markdown_table, write_json  # noqa: E402
from stencil import kernel_run, numpy_run  # noqa: E402

BYTES_PER_ELEMENT = 24          # triad: read b, read c, write a (STREAM's count)
BYTES_PER_UPDATE = 24           # stencil streaming from memory: read u_cur, u_prev, write u_next
CACHE_ROOT = Path("/sys/devices/system/cpu/cpu0/cache")


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sizes", default="8k,256k,80M,llc",
                   help="bytes per array, comma-separated, with k/M/G suffixes (powers of 1000); "
                        "'llc' = 4/3 of the last-level cache (default 8k,256k,80M,llc)")
    p.add_argument("--threads", default="1,2", help="comma-separated thread counts (default 1,2)")
    p.add_argument("--repeats", type=int, default=5, help="timed calls, best reported (default 5)")
    p.add_argument("--min-bytes", type=float, default=2e9,
                   help="triad traffic per timed call for cache-resident sizes (default 2e9)")
    p.add_argument("--spans", type=int, default=200, help="stencil kernel spans (default 200)")
    p.add_argument("--intervals", type=int, default=1000,
                   help="intervals per span, kernel and NumPy (default 1000)")
    p.add_argument("--transits", type=float, default=4.0, help="kernel transits (default 4)")
    p.add_argument("--numpy-spans", default="1000,llc",
                   help="NumPy grid sizes in spans, comma-separated; 'llc': the three level "
                        "arrays twice the last-level cache (default 1000,llc)")
    p.add_argument("--numpy-updates", type=float, default=2e8,
                   help="point-updates per NumPy run, at least 5 levels (default 2e8)")
    p.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    return p.parse_args()


# ------------------------------------------------------------------------------- the machine


def cpu_model() -> str:
    """The CPU model string from /proc/cpuinfo (x86 'model name', else 'Model' / 'Hardware')."""
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return platform.processor() or platform.machine()
    for key in ("model name", "Model", "Hardware", "cpu model"):
        for line in text.splitlines():
            if line.split(":")[0].strip() == key:
                return line.split(":", 1)[1].strip()
    return platform.processor() or platform.machine()


def parse_size(text: str) -> int:
    """'48K' -> 49152 (sysfs sizes are binary); '80M' in --sizes is decimal, see parse_bytes."""
    text = text.strip()
    units = {"K": 2**10, "M": 2**20, "G": 2**30}
    if text[-1:].upper() in units:
        return int(float(text[:-1]) * units[text[-1].upper()])
    return int(text)


def caches() -> list[dict[str, object]]:
    """cpu0's caches: level, type, size (bytes), the CPUs that share it."""
    found = []
    for index in sorted(CACHE_ROOT.glob("index*")):
        try:
            read = lambda name: (index / name).read_text().strip()  # noqa: E731
            found.append({"level": int(read("level")), "type": read("type"),
                          "size_bytes": parse_size(read("size")),
                          "shared_cpu_list": read("shared_cpu_list")})
        except (OSError, ValueError):
            continue
    return found


def cache_size(found: list[dict[str, object]], level: int) -> int:
    """Size (bytes) of the data or unified cache of `level`; 0 if there is none."""
    for c in found:
        if c["level"] == level and c["type"] in ("Data", "Unified"):
            return int(c["size_bytes"])
    return 0


def last_level_size(found: list[dict[str, object]]) -> int:
    """Size of the highest data/unified cache level (bytes); 0 if none is listed."""
    levels = [c for c in found if c["type"] in ("Data", "Unified")]
    return int(max(levels, key=lambda c: c["level"])["size_bytes"]) if levels else 0


def parse_bytes(text: str, llc: int) -> int:
    """'8k' -> 8000, '80M' -> 80e6, 'llc' -> 4/3 LLC rounded up to a MB (at least 80 MB)."""
    text = text.strip()
    if text.lower() == "llc":
        return max(80_000_000, math.ceil(4 * llc / 3 / 1e6) * 1_000_000)
    units = {"K": 1e3, "M": 1e6, "G": 1e9}
    if text[-1:].upper() in units:
        return int(float(text[:-1]) * units[text[-1].upper()])
    return int(float(text))


def human(nbytes: float) -> str:
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if nbytes >= scale:
            return f"{nbytes / scale:.4g} {unit}"
    return f"{nbytes:.0f} B"


def human_binary(nbytes: float) -> str:
    for unit, scale in (("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if nbytes >= scale:
            return f"{nbytes / scale:.4g} {unit}"
    return f"{nbytes:.0f} B"


# ---------------------------------------------------------------------------------- the triad


@nb.njit(parallel=True)
def _first_touch(a, b, c):
    for w in nb.prange(a.shape[0]):
        for i in range(a.shape[1]):
            a[w, i] = 0.0
            b[w, i] = 1.0
            c[w, i] = 2.0


@nb.njit(parallel=True)
def _triad(a, b, c, s, reps):
    """reps passes of a = b + s c; row w of the arrays belongs to worker w."""
    for w in nb.prange(a.shape[0]):
        for r in range(reps):
            sr = s + 1e-9 * r              # a different scalar each pass: no pass is redundant
            for i in range(a.shape[1]):
                a[w, i] = b[w, i] + sr * c[w, i]


def triad(bytes_per_array: int, threads: int, repeats: int, min_bytes: float,
          resident: bool) -> dict[str, object]:
    """Best triad bandwidth (GB/s, 24 B per element and pass) of 3 arrays on `threads`."""
    nb.set_num_threads(threads)
    per_thread = max(1, bytes_per_array // 8 // threads)
    a = np.empty((threads, per_thread))
    b = np.empty_like(a)
    c = np.empty_like(a)
    _first_touch(a, b, c)
    elements = threads * per_thread
    reps = max(1, int(min_bytes // (BYTES_PER_ELEMENT * elements))) if resident else 1
    _triad(a, b, c, 3.0, 1)                                      # compile, warm the caches
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        _triad(a, b, c, 3.0, reps)
        best = min(best, time.perf_counter() - start)
    expected = 1.0 + 2.0 * (3.0 + 1e-9 * (reps - 1))
    if not math.isclose(a[0, 0], expected, rel_tol=1e-12) or a[-1, -1] != a[0, 0]:
        raise RuntimeError(f"triad result {a[0, 0]!r}, expected {expected!r}")
    return {"bytes_per_array": 8 * elements, "threads": threads, "reps": reps,
            "wall_s": best, "gb_per_s": BYTES_PER_ELEMENT * elements * reps / best / 1e9}


# -------------------------------------------------------------------------------- the stencil


def stencil_kernel(spans: int, intervals: int, transits: float, threads: int,
                   repeats: int) -> dict[str, object]:
    """Best point-updates/s of stencil.py's kernel_run."""
    lengths = np.linspace(0.5, 1.5, spans)
    wall, updates = min(kernel_run(lengths, intervals, transits, threads)[:2]
                        for _ in range(repeats))
    return {"spans": spans, "intervals": intervals, "transits": transits, "threads": threads,
            "wall_s": wall, "point_updates": updates, "updates_per_s": updates / wall,
            "span_working_set_bytes": 3 * 8 * (intervals + 1)}


def stencil_numpy(spans: int, intervals: int, updates: float, repeats: int) -> dict[str, object]:
    """Best point-updates/s of stencil.py's numpy_run (one thread)."""
    lengths = np.linspace(0.5, 1.5, spans)
    levels = max(5, round(updates / (spans * (intervals + 1))))
    wall, count = min(numpy_run(lengths, intervals, levels)[:2] for _ in range(repeats))
    return {"spans": spans, "intervals": intervals, "levels": levels, "wall_s": wall,
            "point_updates": count, "updates_per_s": count / wall,
            "level_array_bytes": 8 * spans * (intervals + 1)}


# ------------------------------------------------------------------------------------ report


def where_fits(nbytes: int, l1: int, l2: int, llc: int) -> str:
    if l1 and nbytes <= l1:
        return "L1d"
    if l2 and nbytes <= l2:
        return "L2"
    if llc and nbytes <= llc:
        return "the last-level cache"
    return "memory"


def plural(n: int, word: str) -> str:
    return f"{n} {word}{'' if n == 1 else 's'}"


def times(x: float) -> str:
    return f"{x:.1f}x" if x < 10 else f"{x:,.0f}x"


def roofline_sentence(model: str, found: list, mem: dict, l1bw: dict | None, kern: list,
                      nump: list, intervals: int) -> str:
    """One paragraph: where the kernel and NumPy stand against the memory-bound limit."""
    l1, l2, llc = cache_size(found, 1), cache_size(found, 2), last_level_size(found)
    best = max(kern, key=lambda k: k["updates_per_s"])
    limit = {t: bw / BYTES_PER_UPDATE for t, bw in mem["gb_per_s"].items()}
    bound = limit[best["threads"]] * 1e9
    ws = best["span_working_set_bytes"]
    text = (f"On this machine ({model}; L1d {human_binary(l1)}, L2 {human_binary(l2)}, "
            f"last-level cache {human_binary(llc)} per cpu0's sysfs), the triad streams "
            f"{mem['gb_per_s'][best['threads']]:.1f} GB/s from {mem['fits_in']} on "
            f"{plural(best['threads'], 'thread')} (3 arrays of {human(mem['bytes_per_array'])})")
    if mem["fits_in"] != "memory":
        text += (f" [CAVEAT: these arrays live in {mem['fits_in']}, so this is not a memory "
                 "bandwidth and the 'memory-bound limit' below is a cache-bound one; add 'llc' "
                 "to --sizes]")
    if l1bw:
        text += f" and {l1bw['gb_per_s'][best['threads']]:.0f} GB/s from L1"
    text += (f", so a stencil that streamed its 24 B per point-update (read u_cur and u_prev, "
             f"write u_next) from memory could do at most {bound:.3g} point-updates/s. "
             f"The cable-sweep kernel runs at {best['updates_per_s']:.3g} point-updates/s on "
             f"{plural(best['threads'], 'thread')}, ")
    ratio = best["updates_per_s"] / bound
    text += (f"{times(ratio)} above that memory-bound limit" if ratio >= 1
             else f"{ratio:.2f} of that memory-bound limit")
    text += (f", because each span's three levels ({human(ws)} at {intervals} intervals) stay "
             f"in {where_fits(ws, l1, l2, llc)} while the span is advanced through all its "
             f"levels: it would need {best['updates_per_s'] * BYTES_PER_UPDATE / 1e9:.0f} GB/s "
             "from memory")
    if l1bw:
        frac = best["updates_per_s"] * BYTES_PER_UPDATE / 1e9 / l1bw["gb_per_s"][best["threads"]]
        text += f", {100 * frac:.0f} % of the L1 triad bandwidth"
    text += "."
    for n in nump:
        lim1 = limit.get(1)
        if lim1 is None:
            continue
        r = n["updates_per_s"] / (lim1 * 1e9)
        level = n["level_array_bytes"]
        text += (f" NumPy's whole-grid update ({n['spans']} spans: {human(level)} per level "
                 f"array, {human(3 * level)} for three levels, in "
                 f"{where_fits(3 * level, l1, l2, llc)}) runs at {n['updates_per_s']:.3g} "
                 f"point-updates/s on 1 thread, "
                 + (f"{times(r)} the 1-thread memory-bound limit of {lim1 * 1e9:.3g}"
                    if r >= 1 else f"{r:.2f} of the 1-thread memory-bound limit of "
                                   f"{lim1 * 1e9:.3g}")
                 + " (each level makes about eight whole-array passes through temporaries, "
                   "so it moves several times 24 B per point-update).")
    return text


def main() -> None:
    args = parse_args()
    thread_counts = [int(s) for s in args.threads.split(",") if s.strip()]
    thread_counts = [min(t, nb.config.NUMBA_NUM_THREADS) for t in thread_counts]
    thread_counts = sorted(set(thread_counts))
    found = caches()
    model = cpu_model()
    llc = last_level_size(found)
    sizes = sorted({parse_bytes(s, llc) for s in args.sizes.split(",") if s.strip()})

    triads = []
    for size in sizes:
        resident = bool(llc) and 3 * size <= llc
        row = {"bytes_per_array": size, "resident_in_llc": resident, "gb_per_s": {},
               "runs": {}}
        for t in thread_counts:
            r = triad(size, t, args.repeats, args.min_bytes, resident)
            row["gb_per_s"][t] = r["gb_per_s"]
            row["runs"][t] = r
            row["bytes_per_array"] = r["bytes_per_array"]
        row["fits_in"] = where_fits(3 * row["bytes_per_array"], cache_size(found, 1),
                                    cache_size(found, 2), llc)
        triads.append(row)
        print(f"  triad 3 x {human(size)} done", file=sys.stderr, flush=True)
    mem = max(triads, key=lambda r: r["bytes_per_array"])
    l1_rows = [r for r in triads if r["fits_in"] == "L1d"]
    l1bw = l1_rows[0] if l1_rows else None

    kernel_run(np.linspace(0.5, 1.5, 2), 10, 1.0, 1)            # compile or load from cache
    kern = [stencil_kernel(args.spans, args.intervals, args.transits, t, args.repeats)
            for t in thread_counts]
    # "llc": spans enough for the three level arrays to be twice the last-level cache
    level_llc = math.ceil(2 * llc / 3 / (8 * (args.intervals + 1))) if llc else 20000
    nspans = [level_llc if s.strip().lower() == "llc" else int(float(s))
              for s in args.numpy_spans.split(",") if s.strip()]
    nump = [stencil_numpy(s, args.intervals, args.numpy_updates, max(1, min(args.repeats, 3)))
            for s in nspans]

    print("# Bandwidth: STREAM-like triad and the central-difference stencil's roofline\n")
    print(f"CPU: {model}; {len(found)} cache entries for cpu0; Python "
          f"{platform.python_version()}, numba {nb.__version__}; best of {args.repeats}.\n")
    print(markdown_table(["level", "type", "size", "shared by CPUs"],
                         [[c["level"], c["type"], human_binary(c["size_bytes"]),
                           c["shared_cpu_list"]] for c in found]))
    print("\nTriad a = b + s c, GB/s (24 B per element and pass; 10^9 B):\n")
    headers = ["bytes per array", "3 arrays live in", "passes per call"] + [
        f"{t} thread{'s' if t > 1 else ''} (GB/s)" for t in thread_counts]
    if len(thread_counts) > 1:
        headers.append(f"ratio {thread_counts[-1]}/{thread_counts[0]}")
    rows = []
    for r in triads:
        row = [human(r["bytes_per_array"]), r["fits_in"],
               r["runs"][thread_counts[0]]["reps"]] + [
            f"{r['gb_per_s'][t]:.1f}" for t in thread_counts]
        if len(thread_counts) > 1:
            row.append(f"{r['gb_per_s'][thread_counts[-1]] / r['gb_per_s'][thread_counts[0]]:.2f}")
        rows.append(row)
    print(markdown_table(headers, rows))

    print(f"\nStencil point-updates/s against the memory-bound limit (triad 3 x "
          f"{human(mem['bytes_per_array'])}, in {mem['fits_in']}, / 24 B):\n")
    srows = []
    for k in kern:
        lim = mem["gb_per_s"][k["threads"]] * 1e9 / BYTES_PER_UPDATE
        srows.append([f"cable-sweep kernel, {k['spans']} spans x {k['intervals']} intervals, "
                      f"{k['transits']:g} transits", k["threads"], f"{k['wall_s']:.3f}",
                      f"{k['point_updates']:.3e}", f"{k['updates_per_s']:.3e}",
                      f"{lim:.3e}", f"{k['updates_per_s'] / lim:.2f}",
                      f"{k['updates_per_s'] * BYTES_PER_UPDATE / 1e9:.1f}"])
    lim1 = mem["gb_per_s"].get(1, mem["gb_per_s"][thread_counts[0]]) * 1e9 / BYTES_PER_UPDATE
    for n in nump:
        srows.append([f"NumPy, {n['spans']} spans x {n['intervals']} intervals, {n['levels']} "
                      f"levels ({human(n['level_array_bytes'])} per level array)", 1,
                      f"{n['wall_s']:.3f}", f"{n['point_updates']:.3e}",
                      f"{n['updates_per_s']:.3e}", f"{lim1:.3e}",
                      f"{n['updates_per_s'] / lim1:.2f}",
                      f"{n['updates_per_s'] * BYTES_PER_UPDATE / 1e9:.1f}"])
    print(markdown_table(["implementation", "threads", "wall (s)", "point-updates",
                          "point-updates/s", "memory-bound limit (/s)", "ratio to limit",
                          "24 B x rate (GB/s)"], srows))
    sentence = roofline_sentence(model, found, mem, l1bw, kern, nump, args.intervals)
    print("\n" + sentence)

    if args.json:
        write_json(args.json, {
            "cpu_model": model, "caches": found, "triad": [
                {**r, "gb_per_s": {str(t): v for t, v in r["gb_per_s"].items()},
                 "runs": {str(t): v for t, v in r["runs"].items()}} for r in triads],
            "memory_bandwidth_gb_per_s": {str(t): v for t, v in mem["gb_per_s"].items()},
            "stencil_kernel": kern, "stencil_numpy": nump,
            "bytes_per_update": BYTES_PER_UPDATE, "roofline": sentence,
            "python": platform.python_version(), "numba": nb.__version__})


if __name__ == "__main__":
    main()
