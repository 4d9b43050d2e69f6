"""The one fast-math option the kernels use, and the rule that keeps their results independent
of what was compiled before.

CONTRACT lets LLVM fuse a * b + c into one fused multiply-add (one rounding instead of two;
nothing is reordered, no other fast-math liberty is taken): in the lanes' vector loops about
half the floating-point instructions (the stage sums, the cosine's polynomials, the
controller), and the multi-mode right-hand side that both drivers run. Results stay equal to
the scalar driver's to round-off.

Numba compiles a function that states no `fastmath` with the flags of the first caller that
compiles it, and later callers with the same argument types reuse that compile, in the
process and from the Numba cache. So a kernel compiled with CONTRACT calls only kernels that
state their own `fastmath` (or that Numba inlines into it as IR, inline="always"); every other
kernel is then compiled without it, whoever calls it first (tests/test_architecture.py checks
the rule)."""

CONTRACT = {"contract"}
