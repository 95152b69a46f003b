"""Mistakes read off the learner's source, where the values alone cannot name them.

Two slips of Python itself, which leave no pattern in the numbers that the other hints could recognise:
:func:`none_from_in_place_hint`, a method that works in place and returns None used for its value (``b = b.sort()``,
``return out.sort()``, ``x = np.random.shuffle(x)``: the name holds None from there on), and :func:`xor_power_hint`,
``^`` written for a power (``n ^ 2`` is n XOR 2 in Python; on floats numpy and torch refuse it with words about
"bitwise_xor"). Each is asked only once the function has failed (a wrong value, an error), and named only on evidence:
the None hint where the error's words name a None, or a trace of the failing call sees the name hold None (or the
function return it); the `^` hint where numpy's or torch's error refuses `^` on floats, or where the function, its
`^` rewritten to `**` (recompiled with its globals and closure), then matches the reference, so that a correct `^`
on bits (``dominated ^ 1``, a polarity flipped) is never blamed for another mistake. :func:`stub_raised` tells the
stub's own ``raise NotImplementedError`` (the learner's frame, a raise instruction) from torch's. The source comes from :func:`inspect.getsource`, which reads a
notebook cell as well as a file; where there is none (a builtin, a lambda typed at a prompt) the hints say nothing.
"""
from __future__ import annotations

import ast
import dis
import inspect
import re
import sys
import textwrap
import types
from typing import Callable

from .learner_calls import learner_function, library_file, run
from .outputs import compare_outputs

# methods that change their object in place and return None (ndarray.sort/.fill/.resize, list.sort/.append/...,
# dict.update, random.shuffle); `add` and `pop` are left out: a tensor's `add` and every `pop` return a value
IN_PLACE_METHODS = ("sort", "append", "extend", "insert", "reverse", "shuffle", "fill", "resize", "update", "clear",
                    "remove")

XOR_ERROR_WORDS = ("ufunc 'bitwise_xor'", '"bitwise_xor_cpu"', '"bitwise_xor_cuda"')   # not numpy's "use the bitwise_xor" (a bool -)


def _own(fn: Callable) -> Callable:
    """The learner's function behind the check's notebook-call wrapper (:func:`.learner_calls.learner_function`)."""
    return learner_function(fn)


def _tree(fn: Callable) -> ast.AST | None:
    """The parsed source of ``fn`` (its own def), or None where it cannot be read."""
    try:
        return ast.parse(textwrap.dedent(inspect.getsource(_own(fn))))
    except (OSError, TypeError, SyntaxError, IndentationError, ValueError):
        return None


def _resolve(node: ast.AST, namespace: dict):
    """The object a dotted name (``np.random``) stands for in ``namespace``, or None."""
    if isinstance(node, ast.Name):
        return namespace.get(node.id)
    if isinstance(node, ast.Attribute):
        base = _resolve(node.value, namespace)
        try:            # a property or a module's __getattr__ may raise anything: a hint never crashes the check
            return getattr(base, node.attr, None) if base is not None else None
        except Exception:
            return None
    return None


def _returns_none(call: ast.AST, namespace: dict) -> str | None:
    """The method's name when ``call`` is ``<obj>.<in-place method>(...)`` on an object (not a module's function,
    such as np.sort or torch.sort, which return a value; random.shuffle and np.random.shuffle return None)."""
    if not (isinstance(call, ast.Call) and isinstance(call.func, ast.Attribute)
            and call.func.attr in IN_PLACE_METHODS):
        return None
    receiver = _resolve(call.func.value, namespace)
    if isinstance(receiver, types.ModuleType) and call.func.attr != "shuffle":
        return None
    return call.func.attr


def _in_place_uses(fn: Callable) -> list:
    """(statement node, method, the name assigned or None for a return) for each use of an in-place method's value."""
    tree = _tree(fn)
    if tree is None:
        return []
    namespace = getattr(_own(fn), "__globals__", {})
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            method, target = _returns_none(node.value, namespace), node.targets[0].id
        elif isinstance(node, ast.Return) and node.value is not None:
            method, target = _returns_none(node.value, namespace), None
        else:
            continue
        if method is not None:
            out.append((node, method, target))
    return out


def _none_seen(fn: Callable, case: tuple, observe=None) -> tuple[set, bool]:
    """(the local names seen holding None, whether it returned None) in ``fn``'s own frame, on a traced call."""
    code, names, returned = getattr(_own(fn), "__code__", None), set(), [False]
    if code is None:
        return names, False

    def local(frame, event, arg):
        for name, value in frame.f_locals.items():
            if value is None:
                names.add(name)
        if event == "return" and arg is None:
            returned[0] = True
        return local

    def tracer(frame, event, arg):
        return local if frame.f_code is code else None
    before = sys.gettrace()
    sys.settrace(tracer)
    try:
        run(fn, case[0], case[1], observe)
    except Exception:
        pass
    finally:
        sys.settrace(before)
    return names, returned[0]


def none_from_in_place_hint(fn: Callable, err: BaseException | None = None, case: tuple | None = None,
                            observe=None) -> str | None:
    """A hint where ``fn`` uses the value of a method that works in place and returns None, assigned to one name
    (``b = b.sort()``) or returned (``return out.sort()``), and a None shows: the error ``err`` names one, or a
    traced call on ``case`` ((args, kwargs)) sees the name hold None (or the function return None); else None.
    A torch tensor's ``.sort()`` returns (values, indices), and is never blamed."""
    uses = _in_place_uses(fn)
    if not uses:
        return None
    if err is not None and re.search(r"\bNone(Type)?\b", str(err)):
        node, method, target = uses[0]
    elif case is not None:
        names, returned = _none_seen(fn, case, observe)
        found = [u for u in uses if (u[2] in names if u[2] is not None else returned)]
        if not found:
            return None
        node, method, target = found[0]
    else:
        return None
    what = f"`{target}` is None from there on" if target is not None else "the function returns None"
    line = ast.get_source_segment(textwrap.dedent(inspect.getsource(_own(fn))), node) or ""
    alternative = {"sort": " (for a sorted copy: `np.sort(a)`, `sorted(a)`)",
                   "shuffle": " (for a shuffled copy: `rng.permutation(a)`)"}.get(method, "")
    return (f"`{line.strip()}`: `.{method}(...)` changes its object in place and returns None, so {what}; call "
            f"it on a line of its own and keep using the object{alternative}")


def _number(node: ast.AST) -> bool:
    return isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool)


XOR_HINT = ("`^` is exclusive or (of the bits) in Python, not a power: `n ^ 2` is n XOR 2, and numpy and torch "
            "refuse `^` on floats; write a power with `**` (`x ** 2`, `(I / (I + 1)) ** gamma`)")


class _PowerForXor(ast.NodeTransformer):
    """`a ^ b` and `a ^= b` rewritten as `a ** b` and `a **= b`; counts what it rewrote."""

    def __init__(self):
        self.count = 0

    def visit_BinOp(self, node):
        self.generic_visit(node)
        if isinstance(node.op, ast.BitXor):
            node.op, self.count = ast.Pow(), self.count + 1
        return node

    def visit_AugAssign(self, node):
        self.generic_visit(node)
        if isinstance(node.op, ast.BitXor):
            node.op, self.count = ast.Pow(), self.count + 1
        return node


def recompiled(fn: Callable, transformer: ast.NodeTransformer) -> Callable | None:
    """``fn`` with its source's tree changed by ``transformer``, compiled again with ``fn``'s globals, closure and
    defaults; None where it cannot be (no source, not a def, a closure that does not match)."""
    tree = _tree(fn)
    if tree is None or not tree.body or not isinstance(tree.body[0], ast.FunctionDef):
        return None
    f = _own(fn)
    if not isinstance(f, types.FunctionType):     # a cache's wrapper, a builtin: nothing to compile again
        return None
    fdef = tree.body[0]
    fdef.decorator_list = []
    fdef = transformer.visit(fdef)
    free = f.__code__.co_freevars
    body: list = [fdef]
    if free:           # compiled inside an outer def that binds the same names, so that they stay free variables
        body = [ast.FunctionDef(name="__outer__", args=ast.arguments([], [], None, [], [], None, []),
                                body=[ast.Assign([ast.Name(v, ast.Store())], ast.Constant(None)) for v in free]
                                + [fdef, ast.Return(ast.Name(fdef.name, ast.Load()))], decorator_list=[])]
    module = ast.fix_missing_locations(ast.Module(body=body, type_ignores=[]))
    try:
        code = compile(module, f.__code__.co_filename, "exec")
    except (SyntaxError, ValueError, TypeError):
        return None

    def find(c):
        for const in c.co_consts:
            if isinstance(const, types.CodeType):
                if const.co_name == fdef.name and const.co_firstlineno == fdef.lineno:
                    return const
                inner = find(const)
                if inner is not None:
                    return inner
        return None
    inner = find(code)
    if inner is None:
        return None
    try:
        cells = dict(zip(free, f.__closure__ or ()))
        closure = tuple(cells[v] for v in inner.co_freevars) or None
        new = types.FunctionType(inner, f.__globals__, f.__name__, f.__defaults__, closure)
    except (KeyError, TypeError, ValueError):
        return None
    new.__kwdefaults__ = f.__kwdefaults__
    return new


def xor_power_hint(fn: Callable, err: BaseException | None = None, ex=None, case: tuple | None = None,
                   expected=None) -> str | None:
    """:data:`XOR_HINT` where ``^`` stands for a power: the error ``err`` is numpy's or torch's refusal of `^` on
    floats, or ``fn`` with its `^` rewritten as `**` matches the reference (``expected``; run here where None) on
    ``case`` of exercise ``ex``; else None."""
    if err is not None and any(w in str(err) for w in XOR_ERROR_WORDS):
        return XOR_HINT
    if ex is None or case is None or _own(fn) is not fn:
        return None
    rewrite = _PowerForXor()
    power = recompiled(fn, rewrite)
    if power is None or not rewrite.count:
        return None
    try:
        if expected is None:
            expected = run(ex.reference, case[0], case[1], ex.observe)
        got = run(power, case[0], case[1], ex.observe)
        if ex.compare is not None and ex.observe is None:
            same = ex.compare(got, expected) is None
        else:
            same = compare_outputs(got, expected, ex.rtol, ex.atol) is None
    except Exception:
        return None
    return XOR_HINT if same else None


def stub_raised(err: BaseException) -> bool:
    """``err`` (a NotImplementedError) was raised by a `raise` statement of the learner's own code (the stub's, or
    a helper stub's it calls): the innermost frame is not a library's (torch's nn.Module without a ``forward``
    raises it in Python) and its instruction is a raise, not an operation whose compiled kernel refused (torch's
    `"bitwise_xor_cpu" not implemented for 'Float'` is raised from the learner's line ``x ^ 2``)."""
    tb = err.__traceback__
    if tb is None:
        return True
    while tb.tb_next is not None:
        tb = tb.tb_next
    code = tb.tb_frame.f_code
    if library_file(code.co_filename):
        return False
    for ins in dis.get_instructions(code):
        if ins.offset == tb.tb_lasti:
            return ins.opname == "RAISE_VARARGS"
    return False
