"""Share of the machine's FMA peak that the lanes driver's stage arithmetic reaches.

    python benchmarks/fma_peak.py [--rtol 1e-7] [--repeats 10] [--no-wide]

1. The peak: a small Numba kernel, 64 doubles in L1, each carrying 8 independent chains of 32
   fused multiply-adds (y = y a + b, 2 flops each) written out as straight-line code, so the
   loop across the 64 doubles is vectorised and never waits on an FMA's latency. GFLOP/s on
   1 thread and on 2 threads (two Python threads in the GIL-free kernel), at the vector width
   Numba compiles for by default on this CPU and, in a second process with
   NUMBA_CPU_FEATURES=<host features>,-prefer-256-bit, at 512 bits where the CPU has AVX-512.
2. Flops per attempt, counted from the code the lanes driver runs: the stage chains are
   generated from the tableau (kernels.stages), so their source, and that of the right-hand
   side written out into them, is at hand (`chain.__doc__`); every float +, -, *, / in it is
   a flop (index arithmetic on the lane number and comparisons are not; an FMA is two).
   What lies outside the chain (the error norm, the step-size factor, the metrics, the dense
   output at extrema, the lane bookkeeping) is not counted: the share is that of the stage
   arithmetic, the work an ideal integrator cannot skip.
3. The reference sweep (benchmarks/reference_sweep.py's scene, 10 000 points, rtol given,
   atol = rtol x 1e-4 as in its equal-error ladder), best of --repeats: attempts (accepted +
   rejected steps, the kernel's own counts) x flops per attempt / wall time, against the
   peak of the same thread count.

Prints markdown tables (RESULTS.md, "Share of the FMA peak").
"""

from __future__ import annotations

import argparse
import ast
import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

CHAINS, DEPTH, WIDTH = 8, 32, 64        # independent chains, FMAs per chain, doubles in L1


def _peak_kernel():
    """The straight-line FMA kernel (module docstring, 1) and its repeat loop."""
    import numba as nb
    lines = ["def body(x, out, a, b):", "    for i in range(x.size):"]
    lines += [f"        y{c} = x[i] + {c}.0" for c in range(CHAINS)]
    for _ in range(DEPTH):
        lines += [f"        y{c} = y{c} * a + b" for c in range(CHAINS)]
    lines.append("        out[i] = " + " + ".join(f"y{c}" for c in range(CHAINS)))
    namespace: dict = {}
    exec("\n".join(lines), namespace)
    body = nb.njit(fastmath={"contract"}, nogil=True)(namespace["body"])

    @nb.njit(nogil=True)
    def repeat(x, out, a, b, n):
        for _ in range(n):
            body(x, out, a, b)
            x[0] = out[0] * 1e-30          # the next pass depends on this one
    return body, repeat


def measure_peak(threads: int, passes: int = 400_000) -> dict:
    """Best GFLOP/s of the FMA kernel on `threads` threads (3 tries), and the vector
    registers its code uses."""
    body, repeat = _peak_kernel()
    arrays = [(np.zeros(WIDTH), np.zeros(WIDTH)) for _ in range(threads)]
    repeat(*arrays[0], 0.999, 1e-3, 1)
    asm = body.inspect_asm(body.signatures[0])
    register = "zmm" if "zmm" in asm else "ymm" if "ymm" in asm else "xmm"
    best = 0.0
    for _ in range(3):
        workers = [threading.Thread(target=repeat, args=(x, out, 0.999, 1e-3, passes))
                   for x, out in arrays]
        start = time.perf_counter()
        for w in workers:
            w.start()
        for w in workers:
            w.join()
        wall = time.perf_counter() - start
        best = max(best, 2 * CHAINS * DEPTH * WIDTH * passes * threads / wall / 1e9)
    return {"gflops": best, "register": register}


def _is_index(node: ast.AST, ints: set[str]) -> bool:
    """Whether an expression is integer arithmetic (the lane offsets: integer literals and
    names bound to them, `j`)."""
    if isinstance(node, ast.Constant):
        return isinstance(node.value, int) and not isinstance(node.value, bool)
    if isinstance(node, ast.Name):
        return node.id in ints
    if isinstance(node, ast.BinOp):
        return _is_index(node.left, ints) and _is_index(node.right, ints)
    return False


def count_flops(source: str) -> tuple[int, int]:
    """(float +, -, *, / operations outside calls to `rhs`, calls to `rhs`) in `source`:
    subscripts, integer offsets and bitwise operations are not counted."""
    tree = ast.parse(source)
    ints = {"j"}
    for node in ast.walk(tree):
        if (isinstance(node, ast.Assign) and len(node.targets) == 1
                and isinstance(node.targets[0], ast.Name) and _is_index(node.value, ints)):
            ints.add(node.targets[0].id)
    flops = calls = 0

    def visit(node: ast.AST) -> None:
        nonlocal flops, calls
        if isinstance(node, ast.Subscript):
            visit(node.value)                  # the index is address arithmetic
            return
        if isinstance(node, ast.Call) and getattr(node.func, "id", "") == "rhs":
            calls += 1
        if (isinstance(node, ast.BinOp)
                and isinstance(node.op, (ast.Add, ast.Sub, ast.Mult, ast.Div))
                and not _is_index(node, ints)):
            flops += 1
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(tree)
    return flops, calls


def flops_per_attempt(method: str, parametric: bool, base: bool) -> dict:
    """Flops of one attempt of the lanes driver's stage chain for `method` and the System's
    terms: the chain's own sums plus its right-hand sides."""
    from sweep.kernels import lanes
    terms = ("p" if parametric else "") + ("b" if base else "")     # lanes._chains' kinds
    chains = lanes._chain5 if method == "rk45" else lanes._chain8
    chain = chains.kinds[f"_{terms}" if terms else ""].py_func
    rhs = chain.__globals__["rhs"].py_func
    own, calls = count_flops(chain.__doc__)
    per_rhs, _ = count_flops(rhs.__doc__)
    return {"chain": own, "rhs_calls": calls, "per_rhs": per_rhs,
            "total": own + calls * per_rhs}


def measure_sweep(method: str, rtol: float, threads: int, repeats: int) -> dict:
    """Best wall time (s) and the attempt count of the reference sweep, lanes driver."""
    import reference_sweep as rs
    from bench_common import parameter_table
    from sweep.models.transverse import solve_points
    from sweep.kernels import layout
    from sweep.kernels import oscillator as osc
    from sweep.run import settings_vector
    from sweep.scene import load_scene_text
    scene = load_scene_text(rs.SCENE.format(n=100, rtol=rtol, atol=rtol * 1e-4),
                            overrides={"solver.method": method})
    table, settings = parameter_table(scene), settings_vector(scene)
    solve_points(table[:64], settings, 0, threads=threads)
    best, result = float("inf"), None
    for _ in range(repeats):
        start = time.perf_counter()
        result = solve_points(table, settings, 0, threads=threads)
        best = min(best, time.perf_counter() - start)
    attempts = int(result.counts[:, layout.STEPS].sum() + result.counts[:, layout.REJECTED].sum())
    parametric = bool(np.any(table[:, osc.K1] != 0.0) or np.any(table[:, osc.G1] != 0.0))
    return {"wall": best, "attempts": attempts, "points": table.shape[0],
            "parametric": parametric, "base": False}


def measure_attempt_loop(method: str, rtol: float, attempts: int = 200_000) -> float:
    """Seconds per lane-attempt of the lanes driver's attempt loop alone (kernels.lanes
    `_attempt` or `_attempt8`: the stage chain, the error norm and the stores of the stages),
    repeated on the 16 lanes of the reference sweep's first points with h = 1 ms: the cost of
    the arithmetic the flop count covers, without the controller, the metrics or the lane
    bookkeeping."""
    import numba as nb
    import reference_sweep as rs
    from bench_common import parameter_table
    from sweep.execute import transverse_outputs
    from sweep.kernels import lanes
    from sweep.kernels import oscillator as osc
    from sweep.run import settings_vector
    from sweep.scene import load_scene_text
    scene = load_scene_text(rs.SCENE.format(n=100, rtol=rtol, atol=rtol * 1e-4),
                            overrides={"solver.method": method})
    table, settings = parameter_table(scene)[:lanes.LANES].copy(), settings_vector(scene)
    out = transverse_outputs(lanes.LANES, 0)
    W = np.zeros(lanes.W_ROWS * lanes.LANES)
    switches = osc.terms_of(parametric=True, base=False)
    for j in range(lanes.LANES):
        lanes._load_lane(table, settings, j, j, W, out["states"], out["reals"], out["counts"],
                         out["series"], *switches)
        W[lanes.W_H * lanes.LANES + j] = 1e-3
    attempt = lanes._attempt if method == "rk45" else lanes._attempt8

    @nb.njit(nogil=True)
    def loop(W, rtol, n, parametric, base):
        for _ in range(n):
            attempt(W, rtol, lanes.LANES, parametric, base)

    loop(W, rtol, 1, *switches)
    best = float("inf")
    for _ in range(5):
        start = time.perf_counter()
        loop(W, rtol, attempts, *switches)
        best = min(best, (time.perf_counter() - start) / (attempts * lanes.LANES))
    return best


def measure_all(rtol: float, repeats: int) -> dict:
    """Every figure of this process: peaks on 1 and 2 threads, both methods' sweeps."""
    out = {"peak": {str(t): measure_peak(t) for t in (1, 2)}, "sweeps": {}}
    for method in ("rk45", "dop853"):
        for threads in (1, 2):
            s = measure_sweep(method, rtol, threads, repeats)
            s["flops"] = flops_per_attempt(method, s["parametric"], s["base"])
            s["attempt_loop"] = measure_attempt_loop(method, rtol)
            out["sweeps"][f"{method}/{threads}"] = s
    return out


def wide_features() -> str | None:
    """NUMBA_CPU_FEATURES that let LLVM use 512-bit vectors, or None without AVX-512."""
    import llvmlite.binding as llvm
    llvm.initialize_native_target()
    features = llvm.get_host_cpu_features()
    if not features.get("avx512f", False):
        return None
    return features.flatten() + ",-prefer-256-bit"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--rtol", type=float, default=1e-7,
                   help="rtol of the reference sweep (default 1e-7: final-state error ~1e-5)")
    p.add_argument("--repeats", type=int, default=10, help="sweep repeats, best kept")
    p.add_argument("--no-wide", action="store_true",
                   help="skip the second process compiled for 512-bit vectors")
    p.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.child:
        print(json.dumps(measure_all(args.rtol, args.repeats)))
        return
    runs = {"default width": measure_all(args.rtol, args.repeats)}
    features = None if args.no_wide else wide_features()
    if features:
        env = dict(os.environ, NUMBA_CPU_FEATURES=features,
                   NUMBA_CACHE_DIR=str(Path(os.environ.get("TMPDIR", "/tmp")) / "fma-wide-cache"))
        child = subprocess.run([sys.executable, __file__, "--child", "--rtol", str(args.rtol),
                                "--repeats", str(args.repeats)], env=env, check=True,
                               capture_output=True, text=True)
        runs["512-bit"] = json.loads(child.stdout.strip().splitlines()[-1])
    report(runs, args)


def report(runs: dict, args: argparse.Namespace) -> None:
    """Markdown tables of the peaks and the shares."""
    print(f"# Share of the FMA peak: reference sweep, 10 000 points, rtol {args.rtol:g}, "
          f"atol {args.rtol * 1e-4:g}, lanes driver\n")
    print("| compiled for | threads | FMA peak (GFLOP/s) | registers |")
    print("|---|---|---|---|")
    for name, run in runs.items():
        for t, peak in run["peak"].items():
            print(f"| {name} | {t} | {peak['gflops']:.1f} | {peak['register']} |")
    first = next(iter(runs.values()))
    print("\nFlops per attempt, counted from the generated stage chain (chain sums + right-hand "
          "sides):\n")
    print("| method | chain sums | RHS calls | flops per RHS | flops per attempt |")
    print("|---|---|---|---|---|")
    for key, s in first["sweeps"].items():
        if key.endswith("/1"):
            f = s["flops"]
            print(f"| {key[:-2]} | {f['chain']} | {f['rhs_calls']} | {f['per_rhs']} | "
                  f"{f['total']} |")
    print("\n| compiled for | method | threads | wall (s) | traj/s | attempts/s | stage GFLOP/s "
          "| share of this width's peak | share of the 512-bit peak | attempt loop alone: ns "
          "per lane-attempt, GFLOP/s, share of the wall |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    wide = runs.get("512-bit")
    for name, run in runs.items():
        for key, s in run["sweeps"].items():
            method, threads = key.split("/")
            gflops = s["attempts"] * s["flops"]["total"] / s["wall"] / 1e9
            own = run["peak"][threads]["gflops"]
            wide_peak = wide["peak"][threads]["gflops"] if wide else None
            wide_text = f"{gflops / wide_peak:.1%}" if wide_peak else "n/a"
            alone = s["attempt_loop"]
            loop_share = s["attempts"] * alone / int(threads) / s["wall"]
            print(f"| {name} | {method} | {threads} | {s['wall']:.4f} | "
                  f"{s['points'] / s['wall']:,.0f} | {s['attempts'] / s['wall']:.3e} | "
                  f"{gflops:.1f} | {gflops / own:.1%} | {wide_text} | {alone * 1e9:.1f} ns, "
                  f"{s['flops']['total'] / alone / 1e9:.1f}, {loop_share:.0%} |")


if __name__ == "__main__":
    main()
