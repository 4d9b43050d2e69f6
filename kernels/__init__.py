"""Numba kernels of cable-sweep: pure functions over arrays of parameters, no I/O.

- `dopri5`: the Dormand-Prince 5(4) tableau, one generic step, SciPy RK45's error norm,
  initial-step selection and step-size controller, and the quartic dense output.
- `oscillator`: the modal oscillator right-hand side
  m q'' + c q' + (k0 + k1 cos W t) q + (g0 + g1 cos W t) q^3 + h q^5 = 0.
- `metrics`: in-kernel response metrics (extrema, crossings, state classification).
- `transverse`: the batched driver, one adaptive trajectory per parallel iteration.
"""
