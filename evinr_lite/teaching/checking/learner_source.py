"""Mistakes read off the learner's source, where the values alone cannot name them.

Two slips of Python itself, which leave no pattern in the numbers that the other hints could recognise:
:func:`none_from_in_place_hint`, a method that works in place and returns None used for its value (``b = b.sort()``,
``return out.sort()``, ``x = np.random.shuffle(x)``: the name holds None from there on), and :func:`xor_power_hint`,
``^`` written for a power (``n ^ 2`` is n XOR 2 in Python; on floats numpy and torch refuse it with words about
"bitwise_xor"). Each is asked only once the function has failed (a wrong value, an error), so a correct solution that
happens to use ``^`` on bits is never blamed. The source comes from :func:`inspect.getsource`, which reads a
notebook cell as well as a file; where there is none (a builtin, a lambda typed at a prompt) the hints say nothing.
"""
from __future__ import annotations

import ast
import inspect
import linecache
import textwrap
import types
from typing import Callable

# methods that change their object in place and return None (ndarray.sort/.fill/.resize, list.sort/.append/...,
# dict.update, random.shuffle); `add` and `pop` are left out: a tensor's `add` and every `pop` return a value
IN_PLACE_METHODS = ("sort", "append", "extend", "insert", "reverse", "shuffle", "fill", "resize", "update", "clear",
                    "remove")

XOR_ERROR_WORDS = ("ufunc 'bitwise_xor'", '"bitwise_xor_cpu"', '"bitwise_xor_cuda"')   # not numpy's "use the bitwise_xor" (a bool -)


def _tree(fn: Callable) -> ast.AST | None:
    """The parsed source of ``fn`` (its own def), or None where it cannot be read."""
    try:
        return ast.parse(textwrap.dedent(inspect.getsource(fn)))
    except (OSError, TypeError, SyntaxError, IndentationError, ValueError):
        return None


def _resolve(node: ast.AST, namespace: dict):
    """The object a dotted name (``np.random``) stands for in ``namespace``, or None."""
    if isinstance(node, ast.Name):
        return namespace.get(node.id)
    if isinstance(node, ast.Attribute):
        base = _resolve(node.value, namespace)
        return getattr(base, node.attr, None) if base is not None else None
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


def none_from_in_place_hint(fn: Callable) -> str | None:
    """A hint where ``fn`` uses the value of a method that works in place and returns None: assigned to one name
    (``b = b.sort()``) or returned (``return out.sort()``); else None."""
    tree = _tree(fn)
    if tree is None:
        return None
    namespace = getattr(fn, "__globals__", {})
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            method, what = _returns_none(node.value, namespace), f"`{node.targets[0].id}` is None from there on"
        elif isinstance(node, ast.Return) and node.value is not None:
            method, what = _returns_none(node.value, namespace), "the function returns None"
        else:
            continue
        if method is None:
            continue
        line = ast.get_source_segment(textwrap.dedent(inspect.getsource(fn)), node) or ""
        alternative = {"sort": " (for a sorted copy: `np.sort(a)`, `sorted(a)`)",
                       "shuffle": " (for a shuffled copy: `rng.permutation(a)`)"}.get(method, "")
        return (f"`{line.strip()}`: `.{method}(...)` changes its object in place and returns None, so {what}; call "
                f"it on a line of its own and keep using the object{alternative}")
    return None


def _number(node: ast.AST) -> bool:
    return isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool)


XOR_HINT = ("`^` is exclusive or (of the bits) in Python, not a power: `n ^ 2` is n XOR 2, and numpy and torch "
            "refuse `^` on floats; write a power with `**` (`x ** 2`, `(I / (I + 1)) ** gamma`)")


def xor_power_hint(fn: Callable, err: BaseException | None = None) -> str | None:
    """:data:`XOR_HINT` where ``^`` stands for a power: the error ``err`` is numpy's or torch's refusal of `^` on
    floats, or ``fn``'s source has ``^`` with a number beside it (``n ^ 2``, ``x ^= 2``); else None."""
    if err is not None:
        return XOR_HINT if any(w in str(err) for w in XOR_ERROR_WORDS) else None
    tree = _tree(fn)
    if tree is None:
        return None
    for node in ast.walk(tree):
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.BitXor) and (_number(node.left)
                                                                               or _number(node.right)):
            return XOR_HINT
        if isinstance(node, ast.AugAssign) and isinstance(node.op, ast.BitXor) and _number(node.value):
            return XOR_HINT
    return None


def stub_raised(err: BaseException) -> bool:
    """``err`` (a NotImplementedError) was raised by a `raise` statement (the stub's own, or a helper stub's it
    calls), not by a library's compiled code: torch answers an operation it has no kernel for with a
    NotImplementedError too (`"bitwise_xor_cpu" not implemented for 'Float'`), raised from the learner's line."""
    tb = err.__traceback__
    if tb is None:
        return True
    while tb.tb_next is not None:
        tb = tb.tb_next
    line = linecache.getline(tb.tb_frame.f_code.co_filename, tb.tb_lineno, tb.tb_frame.f_globals)
    return not line or "raise" in line
