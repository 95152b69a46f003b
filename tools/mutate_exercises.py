"""Mutation testing of the exercise checks: does each check catch the wrong solutions learners write?

    python tools/mutate_exercises.py                      # every registered exercise
    python tools/mutate_exercises.py --only anchor,pareto_front
    python tools/mutate_exercises.py --json mutants.json  # also every survivor, machine-readable

Each reference solution's source is parsed and changed in one place at a time, the ways learners err
(:class:`Mutator`): an arithmetic or comparison operator swapped (+ and -, * and /, // and /, < and <= or
>, == and !=), a number moved by one (integers) or halved and doubled (floats), a unary minus dropped, "left"
and "right" swapped (np.searchsorted's side), and / or swapped, a reduction or function swapped for its
twin (sum and mean, max and min, exp and log, floor and ceil, argmax and argmin, cumsum and the values
themselves, a sort or a copy left out), x and y (or H and W) read the wrong way round, a keyword argument
(axis=, side=, keepdims=) left out, a call's first two arguments swapped, the result transposed, a not or
a ~ dropped, an update written as an assignment (= for +=), np.add.at written as a[idx] += v, an
assignment or an update left out. Each mutant is compiled in the reference's own module
and given to :func:`evinr_lite.teaching.exercises.check`. A mutant the check accepts *survives*: it is
either equivalent to the reference on every input (a ``float(n)`` moved by one inside a ``max`` that
never binds, say) or a wrong solution the check misses, which its inputs should then be made to catch.
The report lists every survivor with the line it changed, to be judged by a person.

Deterministic (the checks are seeded); each check has a time limit (``--limit``, seconds) so a mutant
that loops forever counts as caught (it does not pass).
"""
from __future__ import annotations

import argparse
import ast
import contextlib
import inspect
import io
import json
import re
import signal
import sys
import textwrap
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from evinr_lite.teaching import exercises  # noqa: E402

BINOPS = {ast.Add: (ast.Sub,), ast.Sub: (ast.Add,), ast.Mult: (ast.Div,), ast.Div: (ast.Mult, ast.FloorDiv),
          ast.FloorDiv: (ast.Div,), ast.Pow: (ast.Mult,)}
CMPOPS = {ast.Lt: (ast.LtE, ast.Gt), ast.LtE: (ast.Lt, ast.GtE), ast.Gt: (ast.GtE, ast.Lt), ast.GtE: (ast.Gt, ast.LtE),
          ast.Eq: (ast.NotEq,), ast.NotEq: (ast.Eq,)}
TWINS = {"sum": "mean", "mean": "sum", "max": "min", "min": "max", "amax": "amin", "amin": "amax", "exp": "log",
         "log": "exp", "floor": "ceil", "ceil": "floor", "argmax": "argmin", "argmin": "argmax",
         "maximum": "minimum", "minimum": "maximum", "float32": "float64", "float64": "float32",
         "cumsum": "asarray", "log1p": "log", "expm1": "exp", "abs": "asarray", "sqrt": "asarray", "sort": "asarray",
         "copy": "view", "round": "floor", "rint": "floor"}
STRINGS = {"left": "right", "right": "left"}
AXES = {"x": "y", "y": "x", "H": "W", "W": "H", "xi": "yi", "yi": "xi", "dx": "dy", "dy": "dx", "gx": "gy", "gy": "gx"}


class Mutator(ast.NodeTransformer):
    """Applies mutation number ``target`` (in the order the sites are visited) and records what it did;
    with ``target=-1`` it only counts the sites (``self.count``)."""

    def __init__(self, target: int = -1):
        self.target, self.count, self.done = target, 0, None

    def _site(self, node, describe: str, build):
        """One mutation site: apply ``build()`` (the changed node) when it is the target."""
        here = self.count
        self.count += 1
        if here == self.target:
            changed = build()
            before, after = ast.unparse(node), ast.unparse(changed) if not isinstance(changed, ast.Pass) else "pass"
            self.done = (getattr(node, "lineno", 0), f"{describe}: {before[:70]}  ->  {after[:70]}")
            return changed
        return None

    def visit_FunctionDef(self, node):
        # the body only: a learner writes the body, not the signature's defaults or annotations
        node.body = [self.visit(stmt) for stmt in node.body]
        return node

    def visit_BinOp(self, node):
        self.generic_visit(node)
        for swap in BINOPS.get(type(node.op), ()):
            new = self._site(node, f"{type(node.op).__name__} -> {swap.__name__}",
                             lambda swap=swap: ast.copy_location(ast.BinOp(node.left, swap(), node.right), node))
            if new is not None:
                return new
        return node

    def visit_AugAssign(self, node):
        self.generic_visit(node)
        for swap in BINOPS.get(type(node.op), ())[:1]:
            new = self._site(node, f"{type(node.op).__name__}= -> {swap.__name__}=",
                             lambda swap=swap: ast.copy_location(ast.AugAssign(node.target, swap(), node.value), node))
            if new is not None:
                return new
        target = ast.parse(ast.unparse(node.target), mode="eval").body     # the same target, to be stored to
        target.ctx = ast.Store()
        new = self._site(node, "an update written as an assignment (= for +=)",
                         lambda: ast.copy_location(ast.Assign([target], node.value), node))
        if new is not None:
            return new
        new = self._site(node, "the update left out", lambda: ast.copy_location(ast.Pass(), node))
        return node if new is None else new

    def visit_Compare(self, node):
        self.generic_visit(node)
        for k, op in enumerate(node.ops):
            for swap in CMPOPS.get(type(op), ()):
                ops = list(node.ops)
                ops[k] = swap()
                new = self._site(node, f"{type(op).__name__} -> {swap.__name__}",
                                 lambda ops=ops: ast.copy_location(ast.Compare(node.left, ops, node.comparators), node))
                if new is not None:
                    return new
        return node

    def visit_BoolOp(self, node):
        self.generic_visit(node)
        swap = ast.Or if isinstance(node.op, ast.And) else ast.And
        new = self._site(node, f"{type(node.op).__name__} -> {swap.__name__}",
                         lambda: ast.copy_location(ast.BoolOp(swap(), node.values), node))
        return node if new is None else new

    def visit_UnaryOp(self, node):
        self.generic_visit(node)
        if isinstance(node.op, (ast.USub, ast.Not, ast.Invert)):
            what = {ast.USub: "unary minus", ast.Not: "not", ast.Invert: "~"}[type(node.op)]
            new = self._site(node, f"{what} dropped", lambda: node.operand)
            if new is not None:
                return new
        return node

    def visit_Expr(self, node):
        self.generic_visit(node)
        call = node.value
        # np.add.at(a, idx, v) written as a[idx] += v: a repeated index then adds once
        if (isinstance(call, ast.Call) and isinstance(call.func, ast.Attribute) and call.func.attr == "at"
                and isinstance(call.func.value, ast.Attribute) and call.func.value.attr == "add"
                and len(call.args) == 3):
            target = ast.Subscript(call.args[0], call.args[1], ast.Store())
            new = self._site(node, "np.add.at written as a[idx] += v",
                             lambda: ast.copy_location(ast.AugAssign(target, ast.Add(), call.args[2]), node))
            if new is not None:
                return new
        return node

    def visit_Constant(self, node):
        v = node.value
        if isinstance(v, bool) or v is None:
            return node
        if isinstance(v, int):
            for nv in (v + 1, v - 1):
                new = self._site(node, f"{v} -> {nv}", lambda nv=nv: ast.copy_location(ast.Constant(nv), node))
                if new is not None:
                    return new
        elif isinstance(v, float):
            for nv in ((v * 2, v / 2) if v else (1.0,)):
                new = self._site(node, f"{v} -> {nv}", lambda nv=nv: ast.copy_location(ast.Constant(nv), node))
                if new is not None:
                    return new
        elif isinstance(v, str) and v in STRINGS:
            new = self._site(node, f"{v!r} -> {STRINGS[v]!r}",
                             lambda: ast.copy_location(ast.Constant(STRINGS[v]), node))
            if new is not None:
                return new
        return node

    def visit_Call(self, node):
        self.generic_visit(node)
        for k, kw in enumerate(node.keywords):          # a keyword argument forgotten (axis=, keepdims=, side=, ...)
            if kw.arg is None:
                continue
            keywords = node.keywords[:k] + node.keywords[k + 1:]
            new = self._site(node, f"{kw.arg}= left out",
                             lambda keywords=keywords: ast.copy_location(ast.Call(node.func, node.args, keywords), node))
            if new is not None:
                return new
        if len(node.args) >= 2 and not any(isinstance(a, ast.Starred) for a in node.args[:2]):
            args = [node.args[1], node.args[0], *node.args[2:]]   # the first two arguments swapped
            new = self._site(node, "the first two arguments swapped",
                             lambda: ast.copy_location(ast.Call(node.func, args, node.keywords), node))
            if new is not None:
                return new
        return node

    def visit_Return(self, node):
        self.generic_visit(node)
        if node.value is not None and not isinstance(node.value, (ast.Tuple, ast.Constant)):
            new = self._site(node, "the result transposed", lambda: ast.copy_location(
                ast.Return(ast.Attribute(node.value, "T", ast.Load())), node))
            if new is not None:
                return new
        return node

    def visit_Name(self, node):
        swap = AXES.get(node.id)
        if swap is not None and isinstance(node.ctx, ast.Load):
            new = self._site(node, f"{node.id} -> {swap}", lambda: ast.copy_location(ast.Name(swap, ast.Load()), node))
            if new is not None:
                return new
        return node

    def visit_Attribute(self, node):
        self.generic_visit(node)
        twin = TWINS.get(node.attr) or AXES.get(node.attr)
        if twin is not None:
            new = self._site(node, f".{node.attr} -> .{twin}",
                             lambda: ast.copy_location(ast.Attribute(node.value, twin, node.ctx), node))
            if new is not None:
                return new
        return node

    def visit_Assign(self, node):
        self.generic_visit(node)
        # a re-assignment (a name already bound above, e.g. `t_last = t` in a loop) left out
        if len(node.targets) == 1 and isinstance(node.targets[0], (ast.Name, ast.Subscript)):
            new = self._site(node, "the assignment left out", lambda: ast.copy_location(ast.Pass(), node))
            if new is not None:
                return new
        return node


def _function_tree(fn) -> ast.Module:
    tree = ast.parse(textwrap.dedent(inspect.getsource(fn)))
    func = tree.body[0]
    func.decorator_list = []             # compiling must not register the mutant as an exercise
    return tree


def mutants(fn):
    """Yield (line, what changed, the mutant function) for every mutation site of ``fn``."""
    counter = Mutator()
    counter.visit(_function_tree(fn))
    first_line = inspect.getsourcelines(fn)[1]
    for target in range(counter.count):
        m = Mutator(target)
        tree = ast.fix_missing_locations(m.visit(_function_tree(fn)))
        if m.done is None:
            continue
        namespace = dict(fn.__globals__)
        try:
            exec(compile(tree, f"<mutant {fn.__name__} #{target}>", "exec"), namespace)
        except SyntaxError:
            continue
        line, what = m.done
        yield first_line + line - 1, what, namespace[fn.__name__]


class _TimeLimit(Exception):
    pass


def _alarm(signum, frame):
    raise _TimeLimit()


def checked(name: str, fn, limit: float) -> tuple[bool, str]:
    """(whether exercise ``name``'s check accepts ``fn``, the report it prints), within ``limit`` seconds."""
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, limit)
    out = io.StringIO()
    try:
        with contextlib.redirect_stdout(out), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return exercises.check(name, fn), out.getvalue()
    except _TimeLimit:
        return False, f"(stopped after {limit} s)"
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def passes(name: str, fn, limit: float) -> bool:
    """Whether exercise ``name``'s check accepts ``fn`` (quietly, within ``limit`` seconds)."""
    return checked(name, fn, limit)[0]


VERDICTS = ("hint", "shape", "raised", "values")


def verdict(report: str) -> str:
    """How a check rejected a mutant: "hint" (the report names a likely mistake, or an input changed in
    place), "shape" (a wrong shape, dtype or type, said as such), "raised" (the function raised, with the
    line), or "values" (a bare difference: where the values differ, no diagnosis)."""
    if "hint:" in report or "changed its input" in report:
        return "hint"
    if " raised " in report:
        return "raised"
    return "shape" if re.search(r"wrong (shape|dtype|type)|returned a", report) else "values"


def run(names, limit: float = 20.0, log=print) -> dict:
    out = {}
    for name in names:
        ref = exercises.reference(name)
        src_lines = inspect.getsource(inspect.getmodule(ref)).splitlines()
        t0 = time.perf_counter()
        n, survivors, caught = 0, [], dict.fromkeys(VERDICTS, 0)
        for line, what, fn in mutants(ref):
            n += 1
            ok, report = checked(name, fn, limit)
            if ok:
                survivors.append({"line": line, "change": what, "code": src_lines[line - 1].strip()})
            else:
                caught[verdict(report)] += 1
        out[name] = {"mutants": n, "survivors": survivors, "caught": caught,
                     "seconds": round(time.perf_counter() - t0, 1), "module": inspect.getmodule(ref).__name__}
        log(f"{name}: {n} mutants, {len(survivors)} survive; caught with a hint {caught['hint']}, as a wrong shape "
            f"or dtype {caught['shape']}, as an error {caught['raised']}, as different values {caught['values']} "
            f"({out[name]['seconds']} s)")
        for s in survivors:
            log(f"    {out[name]['module']}:{s['line']}  {s['change']}")
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--only", help="comma-separated exercise names (default: every registered one)")
    p.add_argument("--limit", type=float, default=20.0, help="seconds per check before a mutant counts as caught")
    p.add_argument("--json", help="write the results (every survivor) to this file")
    a = p.parse_args(argv)
    names = a.only.split(",") if a.only else exercises.names()
    unknown = sorted(set(names) - set(exercises.names()))
    if unknown:
        p.error(f"unknown exercise(s) {unknown}; known: {', '.join(exercises.names())}")
    out = run(names, a.limit)
    total = sum(r["mutants"] for r in out.values())
    alive = sum(len(r["survivors"]) for r in out.values())
    caught = {k: sum(r["caught"][k] for r in out.values()) for k in VERDICTS}
    print(f"{len(out)} exercises, {total} mutants, {alive} survive ({alive / max(total, 1):.1%}); survivors are "
          "equivalent mutants or wrong solutions the checks miss")
    print(f"caught: {caught['hint']} with a hint naming a likely mistake, {caught['shape']} as a wrong shape or dtype, "
          f"{caught['raised']} as an error with its line, {caught['values']} as different values only (where they differ)")
    if a.json:
        Path(a.json).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
