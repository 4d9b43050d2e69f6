"""The `sweep` command: run a scene, list the built-in scenes.

    sweep run SCENE [-o OUT.nc] [--set KEY=VALUE ...] [--overwrite] [--threads N] [--quiet]
    sweep plot RESULT.nc [-o DIR] [--format png,svg] [--select DIM=VALUE ...] [--dpi N]
    sweep modes SCENE [--modes N] [--set KEY=VALUE ...] [--tolerance 0.01] [--threads N]
    sweep design RESULT.nc [RESULT.nc ...] [--min-frequency HZ] [--max-amplitude M]
                 [--quantity NAME] [--max-deflection M] [--max-strain S] [--max-rms M]
                 [--max-peak M] [--clearance M [--max-probability P]] [--refine [--tolerance M]]
                 [--over AXIS [AXIS ...]] [-o OUT.nc]
    sweep scenes
    sweep keys [SECTION | KEY] [--markdown]
    sweep --version

Exit status: 0 on success, 2 on a user error (one line on stderr: what is wrong, where, and how
to fix it; a sweep too large for memory counts as one), 1 on an internal error; 130, 143, 129
when Ctrl-C, SIGTERM or SIGHUP stopped a run (0 when it came after the result was whole), 141
when the reader of stdout went away.
"""

from __future__ import annotations

import argparse
import os
import shlex
import signal
import sys
import time
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Sequence

from .errors import CableSweepWarning, UserError, one_line
from .version import VERSION, package_version  # noqa: F401  (VERSION: re-exported)

if TYPE_CHECKING:
    import xarray as xr


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (what is wrong, then the usage line) and exit status 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        usage = " ".join(self.format_usage().split())
        self.exit(2, f"sweep: error: {_one_line(message)} ({usage}; see '{self.prog} --help')\n")


def _one_line(text: object) -> str:
    """Every line the CLI prints about a mistake goes through here: one line, escaped, short."""
    return one_line(text)


def _limit(text: str, units: str) -> float:
    """An argparse value: a design limit (sweep.design.limit_value: a plain number in `units`
    or a number with a unit); ArgumentTypeError, one line, otherwise."""
    from .design import limit_value
    try:
        return limit_value(text, units)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _metres(text: str) -> float:
    return _limit(text, "m")


def _hertz(text: str) -> float:
    return _limit(text, "Hz")


def _strain(text: str) -> float:
    """An argparse value: a strain, plain (1, m/m) or with a unit ('300 microstrain',
    '0.03 %'; sweep.design.STRAIN_UNITS)."""
    return _limit(text, "1")


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="sweep", description="Parameter sweeps of nonlinear cable vibration.")
    parser.add_argument("--version", action="version",
                        version=f"sweep (cable-sweep) {package_version()}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    run = sub.add_parser("run", help="run a scene and write the result as netCDF")
    run.add_argument("scene", metavar="SCENE",
                     help="a built-in scene name (see 'sweep scenes') or a .toml file")
    run.add_argument("-o", "--output", metavar="OUT.nc", help="netCDF file to write (atomically)")
    run.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                     help="override a dotted scene key, e.g. --set solver.rtol=1e-9 "
                          "or --set axes.length=[0.5,1.0]")
    run.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    run.add_argument("--threads", type=int, default=None, metavar="N",
                     help="worker threads (default: all)")
    run.add_argument("-q", "--quiet", action="store_true", help="no progress bar or summary")
    run.add_argument("--resume", action="store_true",
                     help="finish an interrupted run: compute only the chunks missing from "
                          "OUT.nc.chunks/")
    run.add_argument("--backend", choices=("threads", "dask"), default=None,
                     help="run the chunks in-process (threads, the default) or on dask")
    run.add_argument("--scheduler", metavar="ADDRESS", default=None,
                     help="dask: an existing scheduler, e.g. tcp://HOST:8786 (implies --backend "
                          "dask; connect only to a cluster you control: it runs code in this "
                          "process; default: a LocalCluster started for the run)")
    run.add_argument("--workers", type=int, default=None, metavar="N",
                     help="dask LocalCluster worker processes (default: one per core)")
    run.add_argument("--chunk-size", type=int, default=None, metavar="N",
                     help="grid points per kernel call or dask task")
    plot = sub.add_parser("plot", help="draw the figures that fit a result (PNG, or other "
                                        "formats on request)")
    plot.add_argument("result", metavar="RESULT.nc", help="a netCDF file written by 'sweep run'")
    plot.add_argument("-o", "--output-dir", metavar="DIR", default=".",
                      help="directory to write the figures to (created; default: the current "
                           "directory); files are named RESULT-FIGURE.FORMAT")
    plot.add_argument("--format", default="png", metavar="png,svg",
                      help="comma-separated figure formats (default: png; also svg, pdf, ...)")
    plot.add_argument("--select", action="append", default=[], metavar="DIM=VALUE",
                      help="fix a swept axis at one of its values (needed for all but two "
                           "axes when a result has more than two), e.g. --select length=0.5")
    plot.add_argument("--dpi", type=float, default=100.0, metavar="N",
                      help="resolution of raster formats in dots per inch (default: 100)")
    modes = sub.add_parser("modes", help="is the number of Galerkin modes enough? run a "
                                         "transverse scene with N and N + 2 modes and compare")
    modes.add_argument("scene", metavar="SCENE",
                       help="a built-in scene name (see 'sweep scenes') or a .toml file")
    modes.add_argument("--modes", type=int, default=None, metavar="N",
                       help="the modes to check (default: the scene's model.modes)")
    modes.add_argument("--set", dest="overrides", action="append", default=[],
                       metavar="KEY=VALUE", help="override a dotted scene key, as for 'run'")
    modes.add_argument("--tolerance", type=float, default=0.01, metavar="REL",
                       help="relative change that counts as converged (default: 0.01)")
    modes.add_argument("--threads", type=int, default=None, metavar="N",
                       help="worker threads (default: all)")
    modes.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    design = sub.add_parser("design", help="the largest span between clamps meeting the "
                                           "criteria, from a result with a length axis (limits "
                                           "in SI, or with a unit: --max-amplitude '2 mm')")
    design.add_argument("result", metavar="RESULT.nc", nargs="*",   # "*": `_design` takes a
                                                                    # file --over swallowed
                        help="a netCDF file written by 'sweep run' with a length axis; several "
                             "(a launch's sine and random results): each is asked the criteria "
                             "it holds, and the shortest span binds")
    design.add_argument("--min-frequency", type=_hertz, default=None, metavar="HZ",
                        help="first natural frequency at least this (Hz)")
    design.add_argument("--max-amplitude", type=_metres, default=None, metavar="M",
                        help="response at most this (m): peak_amplitude of a swept result, "
                             "else amplitude, or --quantity")
    design.add_argument("--quantity", default=None, metavar="NAME",
                        help="the response (in m) --max-amplitude limits: amplitude, "
                             "peak_amplitude, max_deflection, linear_amplitude, ... (not a "
                             "position or a threshold)")
    design.add_argument("--max-deflection", type=_metres, default=None, metavar="M",
                        help="largest deflection anywhere on the span at most this (m): "
                             "max_deflection (one mode: its midspan amplitude)")
    design.add_argument("--max-strain", type=_strain, default=None, metavar="S",
                        help="largest outer-fibre strain at most this (1, e.g. 0.001, or "
                             "'1000 microstrain', '0.1 %%'): "
                             "max_strain, bending at the clamp or midspan plus stretching")
    design.add_argument("--max-rms", type=_metres, default=None, metavar="M",
                        help="random result: RMS midspan deflection, the mean over the "
                             "realisations (rms_deflection_mean), at most this (m)")
    design.add_argument("--max-peak", type=_metres, default=None, metavar="M",
                        help="random result: largest |midspan deflection|, the mean over the "
                             "realisations (peak_deflection_mean), at most this (m)")
    design.add_argument("--clearance", type=_metres, default=None, metavar="M",
                        help="random result: the probability that |midspan deflection| exceeds "
                             "this clearance level (m, one of the result's outputs.clearance) "
                             "at least once in the test, from the crossing rate pooled over the "
                             "realisations, at most --max-probability")
    design.add_argument("--max-probability", type=float, default=None, metavar="P",
                        help="--clearance: the largest exceedance probability (default 0.01, "
                             "i.e. 1 %%)")
    design.add_argument("--refine", action="store_true",
                        help="refine each bracketed span by bisecting on length with runs of "
                             "the result's scene (the frequency criterion needs none; not for "
                             "a random result)")
    design.add_argument("--tolerance", type=_metres, default=None, metavar="M",
                        help="--refine: bisect until the bracket is below this (m, default "
                             "0.001; or with a unit, '1 mm')")
    design.add_argument("--over", nargs="+", action="extend", default=None, metavar="AXIS",
                        help="one span for every value of these axes together (a stepped "
                             "test's base_frequency_ratio and direction, an uncertain "
                             "damping_ratio): the shortest of their spans, binding_AXIS naming "
                             "the value it binds at (not length, not realisation)")
    design.add_argument("-o", "--output", metavar="OUT.nc",
                        help="netCDF file to write the spans to (atomically)")
    design.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    compile_ = sub.add_parser(
        "compile", help="compile the kernels scenes need, ahead of their first run (after "
                        "installing, in an image): a scene's first run then starts at once")
    compile_.add_argument("scenes", nargs="*", metavar="SCENE",
                          help="built-in scene names or .toml files (default: every built-in "
                               "scene)")
    compile_.add_argument("--set", dest="overrides", action="append", default=[],
                          metavar="KEY=VALUE", help="override a dotted scene key, as for run")
    sub.add_parser("scenes", help="list the built-in scenes")
    keys = sub.add_parser("keys", help="every scene key: type, default, units, allowed values")
    keys.add_argument("which", nargs="?", default=None, metavar="SECTION | KEY",
                      help="only this section (e.g. solver) or dotted key (e.g. solver.rtol)")
    keys.add_argument("--markdown", action="store_true",
                      help="the whole reference as a Markdown page (docs/scene-keys.md)")
    return parser


def _summary(ds, seconds: float) -> str:
    """The run's one line: title, points, time, and the count of each state (a time-domain
    run's `state`, a stability chart's `stability`, both where the run made both)."""
    import numpy as np

    def counted(name: str) -> str:
        flags = ds[name].attrs      # CF flag_values / flag_meanings (not 0..n-1 for every kind)
        values = ds[name].values.ravel()
        counts = [(int(np.count_nonzero(values == v)), m) for v, m in
                  zip(np.atleast_1d(flags["flag_values"]), flags["flag_meanings"].split())]
        return ", ".join(f"{c} {m}" for c, m in counts if c)
    names = [n for n in ("state", "stability") if n in ds]
    states = "; ".join((f"{n}: " if len(names) > 1 else "") + counted(n) for n in names)
    n = int(ds.attrs["n_points"])
    ways = (f" ({n // 2} x 2 directions: up, down)" if "direction" in ds[names[0]].dims else "")
    from .errors import escape
    return (f"{escape(str(ds.attrs['title']))}: {n} point{'' if n == 1 else 's'}{ways} in "
            f"{seconds:.2f} s ({states})")


MAX_DPI = 2400.0
"""Highest --dpi: a 7 x 5 inch figure at 2400 dpi is 200 megapixels, more than any print."""


def _run(args: argparse.Namespace) -> int:
    from .io import check_output_path
    from .scene import load_scene, parse_override
    from .run import run

    if args.threads is not None and args.threads < 1:
        raise UserError(f"--threads {args.threads}: must be a positive number of threads "
                        "(give --threads 1 or more, or leave it out to use every core)")
    overrides = dict(parse_override(item) for item in args.overrides)
    if args.scheduler is not None:
        from .execute import check_scheduler
        check_scheduler(args.scheduler, "--scheduler")
        overrides.setdefault("run.backend", "dask")
    for key, value in (("run.backend", args.backend), ("run.chunk_size", args.chunk_size)):
        if value is not None:
            overrides[key] = value
    if args.resume and not args.output:
        raise UserError("--resume: needs -o OUT.nc, the file whose interrupted run to finish")
    if args.quiet and not args.output:
        raise UserError("--quiet without -o: the result would be neither written nor shown "
                        "(give -o OUT.nc to keep it, or drop --quiet to see it)")
    scene = load_scene(args.scene, overrides=overrides)
    _check_dask_flags(args, scene.get("run.backend"))
    if args.workers is not None:     # checked against the backend first: its own line above
        scene = load_scene(args.scene, overrides={**overrides, "run.workers": args.workers})
    if args.output is not None:      # before any work, in one line
        check_output_path(args.output, args.overwrite, scene if args.resume else None)
    started = time.perf_counter()
    from .numba_start import start_without_scipy
    start_without_scipy()        # Numba's registries without importing SciPy (0.15 s)
    ds = run(scene, output=args.output, overwrite=args.overwrite, resume=args.resume,
             threads=args.threads, scheduler=args.scheduler,
             progress=False if args.quiet else None)
    args.complete = True             # a signal from here on finds the result whole
    if not args.quiet:
        line = _summary(ds, time.perf_counter() - started)
        print(line + (f" -> {args.output}" if args.output else ""))
        if not args.output:
            print(ds)
    return 0


def _check_dask_flags(args: argparse.Namespace, backend: str) -> None:
    """Refuse dask options that would be ignored (an option that does nothing is a mistake
    the user wants to hear of before the run, not after it): --scheduler with the threads
    backend, --workers without dask or with --scheduler (an existing cluster has its own)."""
    if args.scheduler is not None and backend != "dask":
        raise UserError("--scheduler: runs the chunks on dask, and --backend threads (or "
                        "run.backend = 'threads') asks for in-process threads (drop one of them)")
    if args.workers is not None and args.scheduler is not None:
        raise UserError(f"--workers {args.workers}: sizes a LocalCluster started for the run, and "
                        "--scheduler names an existing cluster with its own workers (drop "
                        "--workers)")
    if args.workers is not None and backend != "dask":
        raise UserError(f"--workers {args.workers}: sizes the dask backend's LocalCluster, and "
                        "this run uses in-process threads (add --backend dask, or use --threads "
                        "N for threads)")
    if args.workers is not None and args.workers < 0:
        raise UserError(f"--workers {args.workers}: a number of worker processes cannot be "
                        "negative (give 0 for one per core, or a positive count)")
    cores = os.cpu_count() or 1          # the scene's own check (run.workers) says the same
    if args.workers is not None and args.workers > cores:
        raise UserError(f"--workers {args.workers}: {args.workers} worker processes on a machine "
                        f"of {cores} core{'s' if cores != 1 else ''}: more would only compete for "
                        f"them (give --workers {cores} or fewer, or 0 for one per core)")


def _plot(args: argparse.Namespace) -> int:
    import matplotlib
    matplotlib.use("Agg")          # headless: no display needed (the figures never use pyplot)
    from pathlib import Path
    from .plot import load_result, parse_select, plot, save

    if not 1 <= args.dpi <= MAX_DPI:
        raise UserError(f"--dpi {args.dpi:g}: must be a resolution from 1 to {MAX_DPI:g} dots "
                        "per inch (give e.g. --dpi 100 for a screen, 300 for print)")
    formats = [f for f in args.format.split(",") if f.strip()]
    if not formats:
        raise UserError("--format: give at least one format, e.g. --format png,svg")
    select = parse_select(args.select)
    ds = load_result(args.result)
    figures = plot(ds, select)
    if not figures:
        raise UserError(f"result '{args.result}': nothing to plot (no swept axis with more than "
                        "one value and nothing stored over time)")
    stem = Path(args.result).stem
    for path in save(figures, args.output_dir, formats, prefix=f"{stem}-", dpi=args.dpi):
        print(path)
    return 0


def _modes(args: argparse.Namespace) -> int:
    from .convergence import mode_convergence
    from .scene import parse_override
    if args.threads is not None and args.threads < 1:
        raise UserError(f"--threads {args.threads}: must be a positive number of threads "
                        "(give --threads 1 or more, or leave it out to use every core)")
    if not 0.0 < args.tolerance < 1.0:
        raise UserError(f"--tolerance {args.tolerance:g}: must be a relative change between 0 "
                        "and 1, e.g. --tolerance 0.01")
    overrides = dict(parse_override(item) for item in args.overrides)
    report, _, _ = mode_convergence(args.scene, overrides, args.modes, threads=args.threads,
                                    progress=False if args.quiet else None,
                                    tolerance=args.tolerance)
    print(report.text())
    return 0


def _refuse_writing_over_an_input(output: str, inputs: list[str]) -> None:
    """Refuse (one line) an output path that is one of the command's input files (--overwrite
    would replace the result being read with what is made from it)."""
    import os
    for path in inputs:
        try:
            same = os.path.samefile(output, path)
        except OSError:                  # either does not exist (yet): not the same file
            same = False
        if same:
            raise UserError(f"-o {output}: is the input result '{path}'; writing there would "
                            "replace the result with its design: give another file name")


def _take_files_from_over(args: argparse.Namespace) -> None:
    """`sweep design --over AXIS RESULT.nc`: argparse gives --over every word after it, the
    result file too; a word that names a .nc file or an existing path is a result, not an
    axis. Without any result, one line asks for one."""
    over = list(args.over or ())
    files = [w for w in over if w.lower().endswith(".nc") or Path(w).exists()]
    if files:
        args.over = [w for w in over if w not in files] or None
        args.result = list(args.result) + files
    if not args.result:
        raise UserError("design: give the result to design from: sweep design RESULT.nc "
                        "[--min-frequency HZ] [--max-amplitude M] ... (a netCDF file that "
                        "'sweep run' wrote, with a length axis)")
    for word in args.result:
        if not Path(word).exists() and _a_unit(word):
            raise UserError(f"design: result '{word}': no such file, and '{word}' reads as a "
                            "limit's unit: quote a limit with its unit, e.g. "
                            "--max-deflection '2 mm'")


def _a_unit(word: str) -> bool:
    """Whether `word` reads as the unit of a design limit (a length, a frequency or a strain:
    sweep.design.limit_value), as an unquoted '--max-deflection 2 mm' leaves 'mm' behind."""
    from .design import limit_value
    for units in ("m", "Hz", "1"):
        try:
            limit_value(f"1 {word}", units)
            return True
        except ValueError:
            pass
    return False


def _design(args: argparse.Namespace) -> int:
    from .design import NO_CRITERION, interpolated, max_span, refine_span, table
    from .io import check_output_path, write_netcdf
    from .plot import load_result
    _take_files_from_over(args)
    if all(v is None for v in (args.min_frequency, args.max_amplitude, args.max_deflection,
                               args.max_strain, args.max_rms, args.max_peak, args.clearance,
                               args.max_probability)):
        raise UserError(NO_CRITERION)
    if args.tolerance is not None and not args.refine:
        raise UserError(f"design: --tolerance {args.tolerance:g} is the bracket --refine "
                        "bisects to; give --refine too")
    if args.output is not None:
        check_output_path(args.output, args.overwrite)   # before any work, in one line
        _refuse_writing_over_an_input(args.output, args.result)
    if len(args.result) > 1 and args.refine:
        raise UserError("design: --refine takes one result (it runs that result's scene); "
                        "refine each result alone, or leave --refine out")
    criteria = dict(min_frequency=args.min_frequency, max_amplitude=args.max_amplitude,
                    quantity=args.quantity, max_deflection=args.max_deflection,
                    max_strain=args.max_strain, max_rms=args.max_rms,
                    max_peak=args.max_peak, clearance=args.clearance,
                    max_probability=args.max_probability)
    over = tuple(args.over or ())
    loaded = [(path, load_result(path)) for path in args.result]
    if len(loaded) > 1:
        from .governing import governing_span
        result = governing_span(loaded, **criteria, over=over)
    else:
        ds = loaded[0][1]
        result = (refine_span(ds, **criteria, over=over,
                              tolerance=1e-3 if args.tolerance is None else args.tolerance)
                  if args.refine else max_span(ds, **criteria, over=over))
    print(f"{result.attrs['title']} ({result.attrs['criteria']})")
    print(table(result))
    if args.refine:
        print(f"refined: {int(result.attrs['refine_runs'])} engine runs, tolerance "
              f"{result.attrs['refine_tolerance']:g} m (max_span the bracket's passing end)")
    else:
        _say_interpolated(interpolated(result, dict(loaded)), [ds for _, ds in loaded])
    if args.output is not None:
        write_netcdf(result, args.output, overwrite=args.overwrite)
        print(f"-> {args.output}")
    return 0


def _say_interpolated(counts: dict[str, int], results: list[xr.Dataset]) -> None:
    """The lines that say how many spans `sweep design` interpolated between grid lengths
    (sweep.design.interpolated's counts) and what would narrow them."""
    if counts["response"]:
        if len(results) > 1:
            fix = ("--refine runs the engine to bracket it, one sine result at a time; a random "
                   "result's length axis refined (and base.realisations added) narrows it")
        elif "realisation" in results[0].dims:
            fix = "refine the scene's length axis (and add base.realisations) to narrow it"
        else:
            fix = "--refine runs the engine to bracket it"
        print(f"{counts['response']} span(s) interpolated between the grid's lengths, not run "
              "there: a response that peaks between two of them (a resonance) can put the "
              f"true limit shorter; {fix}")
    if counts["frequency"]:
        one = "" if len(results) == 1 else " (on that result alone)"
        print(f"{counts['frequency']} min_frequency span(s) interpolated as log f against "
              "log l, which is exact for unloaded pinned or clamped ends but not for elastic "
              "ones (K = k_t l / EI grows with the span) nor under a constant end load (its "
              f"share of the stiffness grows as l^2); --refine{one} gives the exact span, "
              "without an engine run")


def _compile(args: argparse.Namespace) -> int:
    from . import builtin_scenes
    from .scene import load_scene, parse_override
    from .warmup import warm_up
    overrides = dict(parse_override(item) for item in args.overrides)
    names = args.scenes or list(builtin_scenes())
    scenes = [load_scene(name, overrides=overrides) for name in names]   # every error first
    from .numba_start import start_without_scipy
    start_without_scipy()
    for name, scene in zip(names, scenes):
        started = time.perf_counter()
        seconds = warm_up(scene)
        shown = _one_line(name)
        if seconds > 0.0:
            print(f"{shown}: compiled in {seconds:.1f} s ({time.perf_counter() - started:.1f} s "
                  "with its few points)", flush=True)
        else:
            print(f"{shown}: nothing to compile (every kernel it needs is in Numba's cache)",
                  flush=True)
    return 0


def _scenes() -> int:
    from .scene import builtin_scenes
    scenes = builtin_scenes()
    width = max(len(name) for name in scenes)
    for name, description in scenes.items():
        print(f"{name:<{width}}  {description}")
    return 0


def _keys(args: argparse.Namespace) -> int:
    from .keys import markdown, text
    if args.markdown and args.which is not None:
        raise UserError(f"keys {args.which} --markdown: the Markdown page covers every "
                        "key; leave out the section or key, or drop --markdown")
    sys.stdout.write(markdown() if args.markdown else text(args.which))
    return 0


def _one_line_warnings() -> None:
    """Show cable-sweep's own warnings as one line on stderr, as they happen (installed once,
    however often `main` is called in one process)."""
    original = warnings.showwarning
    if getattr(original, "_cable_sweep", False):
        return

    def show(message, category, filename, lineno, file=None, line=None):  # noqa: ANN001
        if issubclass(category, CableSweepWarning):
            print(f"sweep: warning: {_one_line(message)}", file=sys.stderr)
        else:
            original(message, category, filename, lineno, file, line)
    show._cable_sweep = True  # type: ignore[attr-defined]
    warnings.showwarning = show


def _signal_name(exc: KeyboardInterrupt) -> str:
    """The signal a KeyboardInterrupt stands for: SIGINT (Ctrl-C), or the one
    `execute.terminate_raises` turned into it (SIGTERM, SIGHUP)."""
    return signal.Signals(int(getattr(exc, "signum", 2))).name


def _interrupted(exc: KeyboardInterrupt, args: argparse.Namespace,
                 argv: Sequence[str] | None) -> str:
    """The one line Ctrl-C leaves: what was kept, and the command that finishes the run."""
    from .store import store_path
    output = getattr(args, "output", None)
    if args.command != "run":
        return "interrupted"
    if output is None:
        return ("interrupted: results were not kept (only a run with -o OUT.nc keeps its "
                "finished chunks, in OUT.nc.chunks/, and 'sweep run ... -o OUT.nc --resume' "
                "finishes it)")
    store = store_path(output)
    how = _signal_name(exc)
    how = "interrupted" if how == "SIGINT" else f"{how} received"
    if not store.exists():
        return (f"{how} before any point was finished: nothing kept, no output written (a "
                "first run compiles for up to a minute or two before it solves anything, and "
                "on dask a chunk is kept when its task ends; run the same command again)")
    words = list(sys.argv[1:] if argv is None else argv)
    command = "sweep " + shlex.join(words + ([] if "--resume" in words else ["--resume"]))
    kept = exc.kept_text() if hasattr(exc, "kept_text") else "finished chunks are kept"
    return f"{how}: {kept} in {store}/; finish the run with: {command}"


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `sweep` console script."""
    parser = _parser()
    args, extra = parser.parse_known_args(argv)
    if extra and args.command == "design" and not any(word.startswith("-") for word in extra):
        args.result = [*args.result, *extra]   # result files after an option, in any order
    elif extra:
        parser.parse_args(argv)                # argparse's own one-line usage error, exit 2
    _one_line_warnings()
    try:
        if args.command == "run":
            from .execute import terminate_raises
            with terminate_raises():           # SIGTERM, SIGHUP: as Ctrl-C (one line, --resume)
                return _run(args)
        if args.command == "plot":
            return _plot(args)
        if args.command == "keys":
            return _keys(args)
        if args.command == "design":
            return _design(args)
        if args.command == "modes":
            from .execute import terminate_raises
            with terminate_raises():
                return _modes(args)
        if args.command == "compile":
            return _compile(args)
        return _scenes()
    except UserError as exc:
        print(f"sweep: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except MemoryError:
        if args.command == "plot":
            print(f"sweep: error: {_one_line(args.result)}: the result does not fit in memory "
                  "(plot a smaller result, or select fewer values with --select)",
                  file=sys.stderr)
        else:
            print("sweep: error: the sweep does not fit in memory (use fewer axis points, fewer "
                  "solver.intervals, fewer snapshot_times or a longer outputs.sample_interval)",
                  file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        if getattr(args, "complete", False):
            where = f": {args.output} is whole" if args.output else ""
            print(f"sweep: {_signal_name(exc)} received after the run was complete{where}",
                  file=sys.stderr)
            return 0
        print(f"sweep: {_interrupted(exc, args, argv)}", file=sys.stderr)
        return 128 + int(getattr(exc, "signum", 2))      # 130 for Ctrl-C, 143 SIGTERM, 129 SIGHUP
    except BrokenPipeError:
        # the reader of stdout went away (`sweep design ... | head`): no traceback, and no
        # second one when Python flushes stdout at exit
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141                                       # 128 + SIGPIPE, as a shell reports


if __name__ == "__main__":
    sys.exit(main())
