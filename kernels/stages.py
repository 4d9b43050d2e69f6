"""The lanes driver's stage chains, written out from a Runge-Kutta tableau at import time.

The scalar driver steps with one loop over the tableau (dopri5.explicit_rk_step). The lanes
driver cannot: a loop over the stages inside its loop across the lanes stops LLVM vectorising
that loop. It needs straight-line code, one statement per stage. Rather than a hand-written
copy of each method's stages, `chain_source` writes that code from the tableau (A, B, C) and
`make_chain` compiles it: an inline-always Numba function

    chain(W, j, t, q, v, h, k0q, k0v, parametric, base) -> (kq, kv, qn, vn, s0q, s0v, s1q, s1v, ...)

for the oscillator y = (q, q') (m, m/s) at time t (s), step h (s), with k0 = f(t, y)
(m/s, m/s^2) given. Stage s (1 .. n - 1) is

    q_s  = q + (k0q A[s][0] + k1q A[s][1] + ... + k(s-1)q A[s][s-1]) h
    ksq  = v + (k0v A[s][0] + ... + k(s-1)v A[s][s-1]) h
    ksv  = rhs(W, j, t + C[s] h, q_s, ksq, parametric, base)

then the solution qn = q + h (k0q B[0] + ...), vn likewise, and the last stage
knq = vn, knv = rhs(W, j, t + h, qn, vn, parametric, base): f at the step's end (FSAL). kq
and kv are the tuples (k0 .. kn) of both components (m/s and m/s^2); s_iq, s_iv are the sums
k0 w_i[0] + ... + kn w_i[n] of each weight vector w_i of `sums` (an error estimator's E, not
yet times h). Every sum runs over the stages in order, left to right; with skip_zeros the
terms whose tableau entry is exactly 0 are left out (a sparse tableau: DOP853's). `rhs` is the
driver's right-hand side (for the lanes, lanes._accel: lane j of the working memory W; with
`stage_argument`, a random record's lanes._accel_read, which also takes the stage's number).

The source is generated and exec'd once per process, at import (milliseconds; print it with
`chain_source`). A chain is never compiled on its own: Numba inlines it into its caller's IR
(inline="always"), and the right-hand sides with it, so the caller's loop is straight-line
code, exactly as if the chain were written out in it by hand, and the caller, an ordinary
function of a real module, keeps Numba's on-disk cache. No file is generated.

What that inlining costs is compile time: Numba copies a callee's whole IR into each call site
(every branch, dead ones included, with its own inlined callees), at a cost of about its
variables times its blocks, and each `x if c else y` is three blocks. So the right-hand side
the chain calls is not the System's `acceleration` with its callees (vecmath's cos and sin,
the base excitation) inlined by Numba, but `written_out`: the same function with those
callees written into its source, specialised to one combination of the System's optional
terms (`make_chain(..., switches=...)`), so only the code of those terms is copied, twelve
times for DOP853. `written_out` is a source-level inliner: the same operations in the same
order, written from the one definition in kernels/oscillator.py, not a copy of it. Elsewhere
(the scalar paths) `InlineWhereTrue` keeps such a function a call: inlined only where its
`fast` switch is True (a vector loop across the lanes, where a call stops LLVM vectorising).
"""

from __future__ import annotations

import ast
import builtins
import copy
import functools
import inspect
import textwrap
from typing import Callable, Sequence

import numba as nb

CHAIN_ARGS = "W, j, t, q, v, h, k0q, k0v, parametric, base"


def _literal(value: float) -> str:
    """A float as Python source that reads back as the same double."""
    text = repr(float(value))
    return f"({text})" if text.startswith("-") else text


def _weighted(names: Sequence[str], values: Sequence[float], skip_zeros: bool) -> str:
    """'names[0] * values[0] + names[1] * values[1] + ...' over the entries kept."""
    return " + ".join(f"{name} * {_literal(value)}" for name, value in zip(names, values)
                      if not (skip_zeros and value == 0.0))


def chain_source(A: Sequence[Sequence[float]], B: Sequence[float], C: Sequence[float],
                 sums: Sequence[Sequence[float]] = (), skip_zeros: bool = False,
                 name: str = "chain", stage_argument: bool = False) -> str:
    """Python source of the stage chain of the explicit tableau (A, B, C) (module docstring):
    a function `name`(CHAIN_ARGS) that calls `rhs`, with the tableau's entries written in as
    float literals (each reads back as the same double) and the weighted sums of `sums` (weight
    vectors of length len(B) + 1). With `stage_argument`, each call of rhs gets the stage's
    number (1 .. len(B), the last f(t + h, y_new)) as an eighth argument, an int literal: a
    right-hand side that reads what was computed for that stage before the chain (the lanes'
    record reads, lanes._accel_read)."""
    n = len(B)
    if len(A) != n or len(C) != n or any(len(w) != n + 1 for w in sums):
        raise ValueError("tableau sizes disagree: A and C need len(B) rows, sums len(B) + 1")
    kq = [f"k{s}q" for s in range(n + 1)]
    kv = [f"k{s}v" for s in range(n + 1)]
    lines = [f"def {name}({CHAIN_ARGS}):"]
    for s in range(1, n):
        row = [float(A[s][i]) for i in range(s)]
        dq = _weighted(kq[:s], row, skip_zeros)
        dv = _weighted(kv[:s], row, skip_zeros)
        lines.append(f"    q{s} = q + ({dq}) * h" if dq else f"    q{s} = q")
        lines.append(f"    {kq[s]} = v + ({dv}) * h" if dv else f"    {kq[s]} = v")
        lines.append(f"    {kv[s]} = rhs(W, j, t + {_literal(C[s])} * h, q{s}, {kq[s]}, "
                     f"parametric, base{f', {s}' if stage_argument else ''})")
    weights = [float(x) for x in B]
    sq = _weighted(kq[:n], weights, skip_zeros)
    sv = _weighted(kv[:n], weights, skip_zeros)
    lines.append(f"    qn = q + h * ({sq})" if sq else "    qn = q")
    lines.append(f"    vn = v + h * ({sv})" if sv else "    vn = v")
    lines.append(f"    {kq[n]} = vn")
    lines.append(f"    {kv[n]} = rhs(W, j, t + h, qn, vn, parametric, "
                 f"base{f', {n}' if stage_argument else ''})")
    results = [f"({', '.join(kq)})", f"({', '.join(kv)})", "qn", "vn"]
    for i, w in enumerate(sums):
        values = [float(x) for x in w]
        for k, c in ((kq, "q"), (kv, "v")):
            total = _weighted(k, values, skip_zeros)
            lines.append(f"    s{i}{c} = ({total})" if total else f"    s{i}{c} = 0.0")
            results.append(f"s{i}{c}")
    lines.append(f"    return {', '.join(results)}")
    return "\n".join(lines) + "\n"


class InlineWhereTrue:
    """A Numba inlining decision (inline=InlineWhereTrue(k), a cost model): inline a call
    where its argument k is the constant True (a compile-time switch: oscillator's `fast`, in
    the lanes' vector loops, where a call would stop LLVM vectorising), and compile it once and
    call it elsewhere (where inlining buys nothing and costs compile time: Numba copies the
    callee's whole IR, every branch and its own inlined callees, into each call site). A call
    whose argument k is the caller's own argument is left for the caller's caller to decide
    once it is inlined there. `written_out` makes the same decision at the source level."""

    def __init__(self, position: int):
        self.position = position

    def __call__(self, expr, caller_ir, callee_ir) -> bool:
        from numba.core import ir
        from numba.core.ir_utils import get_definition, guard
        if len(expr.args) <= self.position:
            return False
        value = guard(get_definition, caller_ir, expr.args[self.position])
        return isinstance(value, ir.Const) and value.value is True

    def writes_out(self, args: Sequence[ast.expr]) -> bool:
        """The same decision for a call in source whose arguments are `args`."""
        arg = args[self.position] if len(args) > self.position else None
        return isinstance(arg, ast.Constant) and arg.value is True


@functools.lru_cache(maxsize=None)
def _definition(py_func: Callable) -> ast.FunctionDef:
    """The parsed definition of a Python function (not to be modified)."""
    return ast.parse(textwrap.dedent(inspect.getsource(py_func))).body[0]


class _NotExpandable(Exception):
    """A callee that `inline_source` cannot write out (a loop, a return inside a branch that
    depends on run-time values, a call inside a conditional expression): it stays a call."""


def _inlined(value, args) -> bool:
    """Whether Numba would inline a call of `value` with arguments `args`: a Numba function
    compiled with inline="always", or with an InlineWhereTrue whose switch is True here."""
    options = getattr(value, "targetoptions", None)
    if not (isinstance(options, dict) and hasattr(value, "py_func")):
        return False
    inline = options.get("inline")
    return inline == "always" or (isinstance(inline, InlineWhereTrue) and inline.writes_out(args))


def _constant(value) -> ast.expr:
    """A number, bool or None as an expression (a negative number as a negation, so that the
    source keeps operator precedence: -2.0 ** 2 is not (-2.0) ** 2)."""
    if isinstance(value, (int, float)) and not isinstance(value, bool) and value < 0:
        return ast.UnaryOp(ast.USub(), ast.Constant(-value))
    return ast.Constant(value)


def _is_constant(node: ast.expr) -> bool:
    return isinstance(node, ast.Constant) or (isinstance(node, ast.UnaryOp) and isinstance(
        node.op, ast.USub) and isinstance(node.operand, ast.Constant))


class _Expander:
    """Writes out calls to inline-always Numba functions as statements (`inline_source`)."""

    def __init__(self, namespace: dict):
        self.namespace = namespace          # the globals the written-out source needs
        self.count = 0

    def bind(self, name: str, value) -> None:
        """Make global `name` (value: a module, a function) available to the source."""
        if name in self.namespace and self.namespace[name] is not value:
            raise ValueError(f"two different globals named {name!r}")
        self.namespace[name] = value

    def body(self, statements, env, globals_, out, top) -> bool:
        """Append `statements` (a function body, in the environment `env`: local name ->
        expression) to `out`, with the branches on a switch known here (`x is None`, `x is not
        None`, x a constant) resolved. Returns whether a return was reached; a function's
        result is then in env["<return>"] (`top`: the outermost function, whose return stays
        a return statement)."""
        for stmt in statements:
            if isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Constant):
                continue                                        # a docstring
            if isinstance(stmt, ast.Pass):
                continue
            if isinstance(stmt, ast.Return):
                value = self.expr(stmt.value, env, globals_, out)
                if top:
                    out.append(ast.Return(value))
                elif isinstance(value, ast.Name) or _is_constant(value):
                    env["<return>"] = value
                else:
                    name = self.fresh("result")
                    out.append(ast.Assign([ast.Name(name, ast.Store())], value))
                    env["<return>"] = ast.Name(name, ast.Load())
                return True
            if isinstance(stmt, ast.If):
                known = self.switch(stmt.test, env)
                if known is not None:
                    if self.body(stmt.body if known else stmt.orelse, env, globals_, out, top):
                        return True
                    continue
                test = self.expr(stmt.test, env, globals_, out)
                then, other = [], []
                if (self.body(stmt.body, env, globals_, then, top)
                        | self.body(stmt.orelse, env, globals_, other, top)):
                    if not top:
                        raise _NotExpandable("a return inside a run-time branch")
                out.append(ast.If(test, then or [ast.Pass()], other))
                continue
            if isinstance(stmt, (ast.Assign, ast.AugAssign)):
                value = self.expr(stmt.value, env, globals_, out)
                targets = stmt.targets if isinstance(stmt, ast.Assign) else [stmt.target]
                targets = [self.target(t, env, globals_, out) for t in targets]
                if isinstance(stmt, ast.Assign):
                    out.append(ast.Assign(targets, value))
                else:
                    out.append(ast.AugAssign(targets[0], stmt.op, value))
                continue
            raise _NotExpandable(f"a {type(stmt).__name__} statement")
        return False

    def switch(self, test: ast.expr, env) -> bool | None:
        """The value of `x is None` / `x is not None` where x is a known constant; else None."""
        if (isinstance(test, ast.Compare) and len(test.ops) == 1
                and isinstance(test.ops[0], (ast.Is, ast.IsNot))
                and isinstance(test.left, ast.Name)
                and isinstance(test.comparators[0], ast.Constant)
                and test.comparators[0].value is None):
            bound = env.get(test.left.id)
            if isinstance(bound, ast.Constant):
                return (bound.value is None) == isinstance(test.ops[0], ast.Is)
        return None

    def fresh(self, name: str) -> str:
        self.count += 1
        return f"_{name}{self.count}"

    def target(self, node, env, globals_, out):
        if isinstance(node, ast.Name):
            bound = env[node.id]
            if not isinstance(bound, ast.Name):
                raise _NotExpandable(f"assignment to the constant argument {node.id}")
            return ast.Name(bound.id, ast.Store())
        if isinstance(node, ast.Tuple):
            return ast.Tuple([self.target(e, env, globals_, out) for e in node.elts],
                             ast.Store())
        if isinstance(node, ast.Subscript):
            return ast.Subscript(self.expr(node.value, env, globals_, out),
                                 self.expr(node.slice, env, globals_, out), ast.Store())
        raise _NotExpandable(f"assignment to a {type(node).__name__}")

    def expr(self, node, env, globals_, out):
        """`node` in the environment: locals renamed, arguments substituted, global numbers
        written as literals, calls to inline-always functions written out before it (into
        `out`)."""
        if isinstance(node, ast.Name):
            if node.id in env:
                return copy.deepcopy(env[node.id])
            if node.id in globals_:
                value = globals_[node.id]
                if value is None or isinstance(value, (bool, int, float)):
                    return _constant(value)
                self.bind(node.id, value)
                return ast.Name(node.id, ast.Load())
            if hasattr(builtins, node.id):
                return ast.Name(node.id, ast.Load())
            raise _NotExpandable(f"an unknown name {node.id}")
        if isinstance(node, (ast.IfExp, ast.BoolOp)):
            inner = []          # a call written out here would be evaluated unconditionally
            result = self.generic(node, env, globals_, inner)
            if inner:
                raise _NotExpandable("a call inside a conditional expression")
            return result
        if isinstance(node, ast.Call):
            args = [self.expr(a, env, globals_, out) for a in node.args]
            if node.keywords:
                raise _NotExpandable("a call with keyword arguments")
            callee = self.resolve(node.func, env, globals_)
            if callee is not None and _inlined(callee, args):
                try:
                    inner = []
                    result = self.call(callee, args, inner)
                    out.extend(inner)
                    return result
                except _NotExpandable:
                    pass                                        # stays a call: Numba inlines it
            return ast.Call(self.expr(node.func, env, globals_, out), args, [])
        return self.generic(node, env, globals_, out)

    def generic(self, node, env, globals_, out):
        node = copy.copy(node)
        for field, value in ast.iter_fields(node):
            if isinstance(value, ast.expr):
                setattr(node, field, self.expr(value, env, globals_, out))
            elif isinstance(value, list):
                setattr(node, field, [self.expr(v, env, globals_, out) if isinstance(v, ast.expr)
                                      else v for v in value])
        return node

    def resolve(self, node, env, globals_):
        """The object a call's function expression names (a global, or a module's attribute)."""
        if isinstance(node, ast.Name) and node.id not in env:
            return globals_.get(node.id)
        if isinstance(node, ast.Attribute):
            owner = self.resolve(node.value, env, globals_)
            return getattr(owner, node.attr, None) if owner is not None else None
        return None

    def call(self, function, args, out):
        """Write out function(*args) into `out`; returns the expression of its result."""
        definition = _definition(function.py_func)
        spec = definition.args
        if (spec.vararg or spec.kwarg or spec.kwonlyargs or spec.defaults or spec.posonlyargs
                or len(spec.args) != len(args)):
            raise _NotExpandable("a signature other than plain positional arguments")
        params = [a.arg for a in spec.args]
        assigned = {n.id for n in ast.walk(definition)
                    if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}
        tag = self.fresh(function.py_func.__name__.lstrip("_")) + "_"
        env = {}
        for param, arg in zip(params, args):
            if param not in assigned and (isinstance(arg, ast.Name) or _is_constant(arg)):
                env[param] = arg                               # used as it is
            else:
                out.append(ast.Assign([ast.Name(tag + param, ast.Store())], arg))
                env[param] = ast.Name(tag + param, ast.Load())
        for name in assigned - set(params):
            env[name] = ast.Name(tag + name, ast.Load())
        if not self.body(definition.body, env, function.py_func.__globals__, out, top=False):
            raise _NotExpandable("no return")
        return env["<return>"]


def written_out(function: Callable, constants: dict | None = None) -> tuple[str, dict]:
    """The source of `function` (a Numba function of plain positional arguments) with every
    call to an inline-always Numba function written out in its body, recursively, as Numba's
    inline="always" would inline it: the callee's statements with its locals renamed
    (_<name><n>_<local>), its arguments substituted (each evaluated once, in order), its
    global numbers as literals, and its branches on a compile-time switch resolved (`x is
    None` where the caller passes x as a constant: fast=True, say), so the dead branches are
    not written. A branch on a switch that is an argument of `function` itself (parametric,
    base) stays an `if`, for Numba to prune per specialisation. Same operations in the same
    order, so the same compiled code, but without Numba's cost of inlining: it copies each
    callee's whole IR (every branch, its own inlined callees) into every call site, and each
    copy costs in proportion to the caller's size. A callee this cannot write out (a loop, a
    return inside a run-time branch) stays a call. `constants` (argument name -> None or True)
    specialises `function` to those switches: their branches are resolved too (the arguments
    stay in the signature, unread). Returns (source, the globals it needs)."""
    py_func = function.py_func
    definition = copy.deepcopy(_definition(py_func))
    namespace = {}
    expander = _Expander(namespace)
    params = [a.arg for a in definition.args.args]
    assigned = {n.id for n in ast.walk(definition)
                if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}
    env = {name: ast.Name(name, ast.Load()) for name in set(params) | assigned}
    for name, value in (constants or {}).items():
        if name not in params or name in assigned:
            raise ValueError(f"{name!r} is not an argument {py_func.__name__} only reads")
        env[name] = ast.Constant(value)
    out = []
    expander.body(definition.body, env, py_func.__globals__, out, top=True)
    definition.body = [ast.Expr(ast.Constant(py_func.__doc__ or ""))] + out
    definition.decorator_list = []
    return ast.unparse(ast.fix_missing_locations(definition)) + "\n", namespace


def _inline_outside_chains(expr, caller_ir, callee_ir) -> bool:
    """Numba's inlining decision for a chain's right-hand side (a cost model): inline it into
    the function the chain is inlined into, not into the chain itself. Numba copies a callee's
    whole IR when it inlines it, at a cost in proportion to the callee's size times its
    number of blocks: a chain with its right-hand sides in it is large (the copies took
    seconds of compile time), without them it is a few hundred variables in one block."""
    return not getattr(caller_ir.func_id.func, "stage_chain", False)


@functools.lru_cache(maxsize=None)
def _written_rhs(rhs: Callable, switches: tuple) -> Callable:
    """`rhs` written out for `switches` ((name, None or True) pairs, sorted) as the Numba
    function a chain calls: one per right-hand side and combination of switches, shared by
    every method's chain (writing it out is most of a chain's import time)."""
    rhs_source, rhs_namespace = written_out(rhs, dict(switches))
    exec(compile(rhs_source, f"<right-hand side {rhs.py_func.__name__} {dict(switches)}>",
                 "exec"), rhs_namespace)
    flat = rhs_namespace[rhs.py_func.__name__]
    flat.__doc__ = rhs_source
    return nb.njit(nogil=True, error_model="numpy", inline=_inline_outside_chains)(flat)


def make_chain(A: Sequence[Sequence[float]], B: Sequence[float], C: Sequence[float],
               rhs: Callable, sums: Sequence[Sequence[float]] = (), skip_zeros: bool = False,
               name: str = "chain", switches: dict | None = None,
               stage_argument: bool = False) -> Callable:
    """The stage chain of (A, B, C) (`chain_source`) as an inline-always Numba function that
    calls `rhs` (a Numba function rhs(W, j, t, q, v, parametric, base) -> q'' in m/s^2, with
    `stage_argument` rhs(W, j, t, q, v, parametric, base, stage)), itself written out with its
    callees (`written_out`, specialised to `switches`: e.g. {"parametric": None, "base": True};
    the chain's own parametric and base are then unread) and inlined into the chain's caller."""
    namespace = {"rhs": _written_rhs(rhs, tuple(sorted((switches or {}).items())))}
    source = chain_source(A, B, C, sums, skip_zeros, name, stage_argument)
    exec(compile(source, f"<stage chain {name}>", "exec"), namespace)
    function = namespace[name]
    function.__doc__ = source
    function.stage_chain = True
    return nb.njit(nogil=True, error_model="numpy", inline="always")(function)
