"""Stepped sweeps with continuation: one axis of a transverse scene solved in order.

Along the continuation axis (`[continuation] axis`) every grid point is a dwell of
`solver.t_end` seconds that starts from the final state of the dwell before it (q, q' of every
mode) with the excitation's phase carried on (docs/model.md sec. 6):

    phi_(k+1) = phi_k + w_k T_d      (the base excitation's and the end load's, each)

so the excitation is one continuous signal whose frequency (or level, or load) steps. Each
dwell's clock restarts at 0, the System being autonomous but for the excitation, whose phase
offsets are columns of its row; its metrics (amplitude, settling time, state, ...) are taken
on its own tail window, as for an independent point. The first dwell starts from the scene's
initial conditions; so does a dwell after one that failed (diverged, step too small, too many
steps), its phases from zero: there is no final state to carry on.

The other axes stay parallel: the lines (every combination of the other axes' values) are
dealt out to the threads, each sweeping its share through every dwell with one kernel call a
dwell (`solve_lines`), so a 100-length x 400-frequency stepped map still uses every core.
Directions: "up" (increasing axis values),
"down" (decreasing) or "both" (a `direction` dimension, up then down, each from the initial
conditions). Results are stored in the axis's own order whatever the direction.

Jumps: where a dwell's tail amplitude differs from the previous dwell's (in the sweep's order)
by more than `continuation.jump_ratio`, the response changed branch: the `jump` flag says up
(the amplitude rose) or down (it fell) at that dwell. Swept both ways, a flag stands only where
the up and down sweeps were on different branches at the dwell before it (hysteresis); a steep
slope that both directions follow alike is no jump.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass
from typing import Callable

import numpy as np
import xarray as xr

from sweep.kernels import states as km

DIRECTION_DIM = "direction"
NO_JUMP, JUMP_UP, JUMP_DOWN = 0, 1, 2
JUMP_MEANINGS = "none jump_up jump_down"
FAILED = (km.DIVERGED, km.STEP_TOO_SMALL, km.MAX_STEPS, km.INVALID_INPUT)
MIN_SHARE = 16     # lines a task takes at least (a lanes group: kernels.lanes.LANES)


@dataclass(frozen=True)
class Carry:
    """What a System's rows carry from one dwell to the next (column indices of its rows).

    state: the columns of the initial state (q's then q''s, m and m/s); base_phase,
    load_phase: the phase offsets (rad) of the base excitation and of the end load;
    base_omega, load_omega: their angular frequencies (rad/s); final: where a kernel call's
    outputs hold each point's final state, (n, len(state)): "reals" (the one-mode kernel's
    Q_END and V_END columns) or "final" (the multi-mode kernel's own output). Plain data, so
    that a dask worker can take it.
    """
    state: tuple[int, ...]
    base_phase: int
    load_phase: int
    base_omega: int
    load_omega: int
    final: str

    def final_state(self, out: dict[str, np.ndarray]) -> np.ndarray:
        """Each point's final state (n, len(state)) in a kernel call's outputs."""
        if self.final == "reals":
            from sweep.kernels import layout as tk
            return out["reals"][:, [tk.Q_END, tk.V_END]]
        return out["final"]


def dwell_order(values: np.ndarray, direction: str) -> np.ndarray:
    """Indices of the axis values in the order a sweep visits them: increasing ("up") or
    decreasing ("down") values."""
    order = np.argsort(values, kind="stable")
    return order if direction == "up" else order[::-1]


def _wrap(phase: np.ndarray) -> np.ndarray:
    """A phase (rad) reduced to [-pi, pi]: the same sine, and small enough that w t + phi keeps
    the digits of w t over a dwell."""
    return np.remainder(phase + math.pi, 2.0 * math.pi) - math.pi


@dataclass
class Lines:
    """Lines swept in one order: `points` (lines, dwells) are point indices into the rows,
    one line a row, its dwells along it; `order` the visiting order of the dwells
    (`dwell_order`); `outputs` (by name, first axis = points) receive each dwell's results.
    Resumed lines have `begun` (one per line) dwells of `order` done already and start from
    `carried` (lines, len(state) + 2): each line's state, base phase and load phase after
    them."""
    points: np.ndarray
    order: np.ndarray
    outputs: dict[str, np.ndarray]
    begun: np.ndarray | None = None
    carried: np.ndarray | None = None


# record(lines, points, out, done, carried): a dwell of some of `lines` (a Lines) finished at
# `points` with kernel outputs `out`; `done` dwells of each of those lines are now finished
# and `carried` is what their next dwell starts from (as Lines.carried).
Record = Callable[[Lines, np.ndarray, dict, np.ndarray, np.ndarray], None]


def write_outputs(lines: Lines, points: np.ndarray, out: dict, done: np.ndarray,
                  carried: np.ndarray) -> None:
    """The plain Record: a dwell's results into its lines' outputs."""
    for name, values in out.items():
        lines.outputs[name][points] = values


def solve_lines(rows: np.ndarray, groups: list[Lines], carry: Carry, dwell: float,
                solve: Callable[[np.ndarray], dict], workers: int = 1,
                stop: threading.Event | None = None, record: Record = write_outputs) -> bool:
    """Sweep every line of `groups` through its dwells; `rows` are the kernel rows of all
    points (a line's initial conditions are those of its first dwell's row).

    solve(rows) runs the kernel on a batch of rows (on one thread) and returns its outputs by
    name; dwell: the dwell time solver.t_end (s); workers: threads; record: where each dwell's
    results go (write_outputs; a stepped chunk also keeps the lines' progress, to resume a
    line part-way). The work is cut into tasks, a group and a share of its lines each, the
    lines dealt out in turn so that the shares cost alike (a short span takes more steps than
    a long one); each task sweeps its lines through all the dwells, so no thread waits for
    another between dwells. A line's results do not depend on its share or on the number of
    threads. With `stop` set (an interrupt) no new dwell starts: the lines are left
    unfinished. Returns whether every line ran all its dwells."""
    n_lines = sum(g.points.shape[0] for g in groups)
    # shares of at least one lanes group each: fewer lines than that a call leaves lanes idle,
    # and two such calls side by side took longer than one thread doing both (measured)
    per_group = max(1, min(n_lines // (MIN_SHARE * len(groups)), -(-workers // len(groups))))
    tasks = []
    for g in groups:
        for i in range(per_group):
            if g.points[i::per_group].shape[0]:
                tasks.append(Lines(g.points[i::per_group], g.order, g.outputs,
                                   *[None if a is None else a[i::per_group]
                                     for a in (g.begun, g.carried)]))

    def run(task: Lines) -> bool:
        return _sweep_lines(rows, task, carry, dwell, solve, record, stop)

    if workers <= 1 or len(tasks) == 1:
        return all([run(task) for task in tasks])
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(min(workers, len(tasks)), thread_name_prefix="cable-sweep") as pool:
        return all([future.result() for future in [pool.submit(run, task) for task in tasks]])


def _sweep_lines(rows: np.ndarray, lines: Lines, carry: Carry, dwell: float,
                 solve: Callable[[np.ndarray], dict], record: Record,
                 stop: threading.Event | None = None) -> bool:
    """The dwells of `lines` not yet done, in its order, one kernel call a dwell for all the
    lines (resumed lines at different dwells side by side, each leaving when done); with
    `stop` set, no further dwell. Returns whether the lines ran all their dwells."""
    columns = list(carry.state)
    points, order = lines.points, lines.order
    n = points.shape[0]
    first = rows[points[:, order[0]]][:, columns]      # the scene's initial conditions
    begun = np.zeros(n, np.int64) if lines.begun is None else np.asarray(lines.begun, np.int64)
    carried = np.column_stack([first, np.zeros(n), np.zeros(n)])
    if lines.carried is not None:
        carried[begun > 0] = lines.carried[begun > 0]
    for step in range(len(order) - int(begun.min(initial=len(order)))):
        if stop is not None and stop.is_set():
            return False
        active = np.flatnonzero(begun + step < len(order))
        at = points[active, order[begun[active] + step]]
        state, phase_b, phase_w = (carried[active, :-2], carried[active, -2],
                                   carried[active, -1])
        batch = rows[at].copy()
        batch[:, columns] = state
        batch[:, carry.base_phase] = phase_b
        batch[:, carry.load_phase] = phase_w
        out = solve(batch)
        failed = np.isin(out["states"], FAILED)
        carried[active] = np.column_stack([
            np.where(failed[:, None], first[active], carry.final_state(out)),
            np.where(failed, 0.0, _wrap(phase_b + batch[:, carry.base_omega] * dwell)),
            np.where(failed, 0.0, _wrap(phase_w + batch[:, carry.load_omega] * dwell))])
        record(lines, at, out, begun[active] + step + 1, carried[active])
    return True


def jumps(amplitude: np.ndarray, states: np.ndarray, axis: int, order: np.ndarray,
          ratio: float) -> np.ndarray:
    """The jump flag of every point (grid shape, int8): JUMP_UP at the dwell whose tail
    amplitude is more than `ratio` times the previous dwell's in the sweep's `order` along
    `axis`, JUMP_DOWN where it is less than 1/ratio of it, NO_JUMP elsewhere (and where either
    dwell failed or has no amplitude). Consecutive flags of one sense all stand (`first_only`
    keeps the first of each run)."""
    a = np.moveaxis(amplitude, axis, -1)[..., order]
    ok = ~np.isin(np.moveaxis(states, axis, -1)[..., order], FAILED) & np.isfinite(a)
    flags = np.zeros(a.shape, np.int8)
    prev, cur = a[..., :-1], a[..., 1:]
    both = ok[..., :-1] & ok[..., 1:]
    with np.errstate(divide="ignore", invalid="ignore"):
        flags[..., 1:] = np.where(both & (cur > ratio * prev), JUMP_UP,
                                  np.where(both & (cur * ratio < prev), JUMP_DOWN, NO_JUMP))
    back = np.empty_like(flags)
    back[..., order] = flags
    return np.moveaxis(back, -1, axis)


def first_only(flags: np.ndarray, axis: int, order: np.ndarray) -> np.ndarray:
    """`flags` with each run of consecutive flags of one sense (in the sweep's `order` along
    `axis`) reduced to its first: a jump that takes more than one dwell (the first one still
    ringing down from the old branch) is flagged once. A sweep run both ways applies this
    after `branches_differ`: a steep slope flagged just before a jump is dropped there first,
    and the jump keeps its own flag (collapsed before, the slope took the jump's flag with
    it)."""
    f = np.moveaxis(flags, axis, -1)[..., order].copy()
    repeated = np.zeros(f.shape, bool)
    repeated[..., 1:] = (f[..., 1:] != NO_JUMP) & (f[..., 1:] == f[..., :-1])
    f[repeated] = NO_JUMP
    back = np.empty_like(f)
    back[..., order] = f
    return np.moveaxis(back, -1, axis)


def branches_differ(flags: list[np.ndarray], amplitudes: list[np.ndarray], axis: int,
                    orders: tuple[np.ndarray, ...], ratio: float) -> list[np.ndarray]:
    """The flags of a sweep run both ways (up, down: `jumps`' flags, the tail amplitudes in
    grid shape), kept only at jumps: where the dwell before the flagged one (in that sweep's
    order) has up and down amplitudes more than `ratio` apart, i.e. the sweep leaves a branch
    the other direction is not on. A steep slope that both directions climb alike (no
    hysteresis) is flagged by `jumps` in both and here in neither."""
    up, down = (np.moveaxis(a, axis, -1) for a in amplitudes)
    with np.errstate(divide="ignore", invalid="ignore"):
        differ = (np.maximum(up, down) > ratio * np.minimum(up, down)) \
            & np.isfinite(up) & np.isfinite(down)
    kept = []
    for f, order in zip(flags, orders):
        f = np.moveaxis(f, axis, -1).copy()
        before = np.zeros(f.shape, bool)          # whether the dwell before, in this order,
        before[..., order[1:]] = differ[..., order[:-1]]     # is where the branches differ
        f[~before] = NO_JUMP
        kept.append(np.moveaxis(f, -1, axis))
    return kept


def jump_attrs(axis_name: str, ratio: float, both: bool) -> dict[str, object]:
    """CF flag attributes of the `jump` variable (both: the sweep ran both ways, and a flag
    stands only where the up and down branches differ, `branches_differ`)."""
    where = ("where the up and down sweeps are on different branches" if both else
             "(run both ways to tell a jump from a steep slope)")
    return {"units": "1", "flag_values": np.array([NO_JUMP, JUMP_UP, JUMP_DOWN], np.int8),
            "flag_meanings": JUMP_MEANINGS,
            "long_name": f"jump of the tail amplitude from the previous step along {axis_name}",
            "comment": f"jump of the tail amplitude from the previous step along {axis_name} "
                       f"in the sweep's direction (by more than a factor {ratio:g}) {where}"}


def direction_coordinate(directions: list[str], long_name: str = "direction of the stepped "
                         "sweep along the continuation axis (up: increasing values)"
                         ) -> xr.DataArray:
    """The `direction` coordinate of a result swept both ways."""
    return xr.DataArray(np.array(directions, dtype=object), dims=DIRECTION_DIM,
                        attrs={"long_name": long_name})
