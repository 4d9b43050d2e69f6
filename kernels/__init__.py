"""Numba kernels of cable-sweep: pure functions over arrays of parameters, no I/O.

- `dopri5`: the Dormand-Prince 5(4) tableau, one generic step, SciPy RK45's error norm,
  initial-step selection and step-size controller, and the quartic dense output.
- `dop853`: the Dormand-Prince 8(5,3) tableau and SciPy DOP853's error norm (solver.method =
  "dop853"), its seventh-order dense output and the quintic Hermite one.
- `stages`: the lanes' stage chains, written out from a tableau at import.
- `oscillator`: the transverse System's right-hand side, the modal oscillator
  m q'' + c q' + (k0 + k1 cos W t) q + (g0 + g1 cos W t) q^3 + h q^5 = -m G a_b(t).
- `excitation`: the base excitation a_b(t) (fixed or swept sine, or a random record), one
  block of columns both Systems read.
- `metrics`: the reductions of a finished trajectory (settling, period-k orbits, drift, a
  sweep's peak frequency and envelope); `states`, `layout`: plain constants (the state table,
  the settings vector and output columns).
- `trajectory`: one trajectory's state machine (SciPy's RK45 or DOP853 step sequence) and the
  Observer (the metrics of each step).
- `transverse`: the scalar driver, one adaptive trajectory after another over a block of
  points, and the classification of a finished one.
- `lanes`: the lock-step SIMD driver, 16 trajectories side by side (the default).
- `modes`: the multi-mode System; `modal_driver`, `modal_lanes`: its scalar and lock-step
  drivers.
- `floquet`: Floquet multipliers of the linearised span over one load period.
- `vecmath`: vectorisable cos, sin and powers for the lanes' loops.
- `longitudinal`, `wave_layout`: the central-difference kernel of the longitudinal wave and
  its layouts.
"""
