"""Numba kernels of cable-sweep: pure functions over arrays of parameters, no I/O.

- `dopri5`: the Dormand-Prince 5(4) tableau, one generic step, SciPy RK45's error norm,
  initial-step selection and step-size controller, and the quartic dense output.
- `dop853`: the Dormand-Prince 8(5,3) tableau and SciPy DOP853's error norm (solver.method =
  "dop853"), and the quintic Hermite dense output it uses.
- `oscillator`: the modal oscillator right-hand side
  m q'' + c q' + (k0 + k1 cos W t) q + (g0 + g1 cos W t) q^3 + h q^5 = 0.
- `metrics`: in-kernel response metrics (extrema, crossings, state classification).
- `trajectory`: one trajectory's state machine (SciPy's RK45 or DOP853 step sequence,
  metrics per step).
- `transverse`: the scalar driver, one adaptive trajectory after another over a block of points.
- `lanes`: the lock-step SIMD driver, 16 trajectories side by side (the default).
- `vecmath`: vectorisable cos and powers for the lanes' loops.
"""
