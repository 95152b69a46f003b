"""Mistakes read off the learner's source, where the values alone cannot name them.

Two slips of Python itself, which leave no pattern in the numbers that the other hints could recognise:
:func:`none_from_in_place_hint`, a method that works in place and returns None used for its value (``b = b.sort()``,
``return out.sort()``, ``x = np.random.shuffle(x)``: the name holds None from there on), and :func:`xor_power_hint`,
``^`` written for a power (``n ^ 2`` is n XOR 2 in Python; on floats numpy and torch refuse it with words about
"bitwise_xor"). Each is asked only once the function has failed (a wrong value, an error), and named only on a
proof: the function rewritten and compiled again with its globals and closure (:func:`recompiled`; the learner's
own function, behind the check's notebook-call wrapper and behind its decorators) and called as the check calls
it. The None hint where the function, the method called on a line of its own and the name kept holding the object,
matches the reference (or, where the function raised or returned None or another shape, no longer fails but in its
numbers); the `^` hint where numpy's or torch's error refuses `^` on floats, or where the function, its `^`
rewritten to `**`, matches while with `^ b` removed it does not (a constant 0, 1, True or False after `^` is a bit
flipped, never a power), so that a correct `^` on bits (``dominated ^ 1``) or a torch ``.sort()`` (values and
indices) is never blamed for another mistake; where it cannot be compiled again, no hint. :func:`stub_raised` tells the
stub's own ``raise NotImplementedError`` (the learner's frame, a raise instruction) from torch's. The source comes from :func:`inspect.getsource`, which reads a
notebook cell as well as a file; where there is none (a builtin, a lambda typed at a prompt) the hints say nothing.
"""
from __future__ import annotations

import ast
import copy
import dis
import inspect
import textwrap
import types
from typing import Callable

import numpy as np

from .learner_calls import learner_function, library_file, run
from .outputs import compare_outputs, not_finite

# methods that change their object in place and return None (ndarray.sort/.fill/.resize, list.sort/.append/...,
# dict.update, random.shuffle); `add` and `pop` are left out: a tensor's `add` and every `pop` return a value
IN_PLACE_METHODS = ("sort", "append", "extend", "insert", "reverse", "shuffle", "fill", "resize", "update", "clear",
                    "remove")

XOR_ERROR_WORDS = ("ufunc 'bitwise_xor'", '"bitwise_xor_cpu"', '"bitwise_xor_cuda"')   # not numpy's "use the bitwise_xor" (a bool -)


def _own(fn: Callable) -> Callable:
    """The learner's own function: behind the check's notebook-call wrapper (:func:`.learner_calls.learner_function`)
    and behind its decorators (``@torch.no_grad()``, a functools.wraps wrapper: :func:`inspect.unwrap`), so that
    its source, globals, closure and defaults are read off one function."""
    own = learner_function(fn)
    try:
        return inspect.unwrap(own)
    except (ValueError, TypeError):
        return own


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


_OBJECT = "_in_place_object_"


class _ObjectForNone(ast.NodeTransformer):
    """``b = <obj>.sort(...)`` rewritten as ``_o = <obj>; _o.sort(...); b = _o`` (``return <obj>.sort()`` as
    ``...; return _o``): the method called on a line of its own and the name kept holding the object; for a
    module's ``shuffle`` (``x = np.random.shuffle(x)``), the call on its own and the name given its argument.
    Counts what it rewrote."""

    def __init__(self, namespace: dict, only: tuple | None = None):
        self.namespace, self.count, self.only = namespace, 0, only    # only: the (line, column) of one use

    def _rewrite(self, node, call, keep):
        if _returns_none(call, self.namespace) is None:
            return node
        if self.only is not None and (node.lineno, node.col_offset) != self.only:
            return node
        receiver = call.func.value
        if isinstance(_resolve(receiver, self.namespace), types.ModuleType):       # random.shuffle(x)
            if not call.args or isinstance(call.args[0], ast.Starred):
                return node
            out = [ast.Expr(call), keep(call.args[0])]
        else:
            call.func.value = ast.Name(_OBJECT, ast.Load())
            out = [ast.Assign([ast.Name(_OBJECT, ast.Store())], receiver), ast.Expr(call),
                   keep(ast.Name(_OBJECT, ast.Load()))]
        self.count += 1
        return [ast.copy_location(n, node) for n in out]

    def visit_Assign(self, node):
        if len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            name = node.targets[0].id
            return self._rewrite(node, node.value, lambda v: ast.Assign([ast.Name(name, ast.Store())], v))
        return node

    def visit_Return(self, node):
        if node.value is None:
            return node
        return self._rewrite(node, node.value, lambda v: ast.Return(v))


def _outcome(got, expected, ex) -> str:
    """"match"; "values" where only the numbers differ (the reference's type and shape, finite where the
    reference is); else "other" (None returned, another type or shape, NaN or inf; by an exercise's own
    comparison, any difference)."""
    if ex.compare is not None and ex.observe is None:
        return "match" if ex.compare(got, expected) is None else "other"
    problem = compare_outputs(got, expected, ex.rtol, ex.atol)
    if problem is None:
        return "match"
    return "values" if problem.values and not (not_finite(got) and not not_finite(expected)) else "other"


def _run_outcome(fn: Callable, ex, case: tuple, expected, call_as) -> str:
    """:func:`_outcome` of ``fn`` called as the check calls the learner's (``call_as``) on ``case`` of exercise
    ``ex``, against the reference's ``expected`` (run here where None); "raised" where either raises."""
    try:
        if expected is None:
            expected = run(ex.reference, case[0], case[1], ex.observe)
        got = run(call_as(fn) if call_as is not None else fn, case[0], case[1], ex.observe)
        return _outcome(got, expected, ex)
    except Exception:
        return "raised"


def _matches_reference(fn: Callable, ex, case: tuple, expected, call_as) -> bool:
    return _run_outcome(fn, ex, case, expected, call_as) == "match"


_RAISED = object()      # none_from_in_place_hint's ``got`` where the learner's call raised


def none_from_in_place_hint(fn: Callable, ex=None, case: tuple | None = None, expected=None,
                            call_as: Callable | None = None, got=_RAISED) -> str | None:
    """A hint where ``fn`` uses the value of a method that works in place and returns None, assigned to one name
    (``b = b.sort()``) or returned (``return out.sort()``), and that None made the failure on ``case`` of exercise
    ``ex``: the function rewritten to call the method on a line of its own and keep the object
    (:class:`_ObjectForNone`, compiled again with its globals and closure), called as the check calls ``fn``
    (``call_as``), matches the reference (``expected``; run here where None), or, where ``fn`` raised (``got``
    left out) or returned ``got`` of another type or shape than the reference's (None, NaN), no longer fails so:
    only its numbers differ (a second mistake, such as sorting what the reference keeps in order). Else None, and
    None where it cannot be compiled again. A torch tensor's ``.sort()`` returns (values, indices): rewritten, it
    raises or stops matching."""
    if ex is None or case is None:
        return None
    uses = sorted(_in_place_uses(fn), key=lambda u: (u[0].lineno, u[0].col_offset))
    if not uses:
        return None
    try:
        if expected is None:
            expected = run(ex.reference, case[0], case[1], ex.observe)
        before = "raised" if got is _RAISED else _outcome(got, expected, ex)
    except Exception:
        return None
    namespace = getattr(_own(fn), "__globals__", {})

    def proven(only) -> bool:
        rewrite = _ObjectForNone(namespace, only)
        kept = recompiled(fn, rewrite)
        if kept is None or not rewrite.count:
            return False
        after = _run_outcome(kept, ex, case, expected, call_as)
        return after == "match" or (after == "values" and before in ("raised", "other"))
    # each use alone first, so that the one named is the one whose None made the failure (not a harmless
    # `note = log.append(...)` before it); all of them together where it takes more than one
    chosen = next((u for u in uses if proven((u[0].lineno, u[0].col_offset))), None) if len(uses) > 1 else None
    if chosen is None:
        if not proven(None):
            return None
        chosen = uses[0]
    node, method, target = chosen
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


def _identity_exponent(node: ast.AST) -> bool:
    """A constant 0, 1, True or False: `x ** 1 == x` and `x ** 0 == 1`, so `^ 1` as a power proves nothing (and
    `^ 1`, `^ True` flip a bit, which is what they mean more often)."""
    return isinstance(node, ast.Constant) and type(node.value) in (int, bool) and node.value in (0, 1)


_GUARDED_POWER = "_evinr_guarded_power_"    # the name the proof's rewrite calls (a closure cell, not a global)


def guarded_power(a, b):
    """``a ** b`` for the `^`-as-power proof, refused (OverflowError) where both are whole numbers and the power
    would be huge: a learner's `^` on integers (a hash's `seed ^= s + 0x9e3779b9`) is often a real exclusive or,
    and as a power it could take longer than any check (2 ** 0x9e3779b9) or size a loop (``range(n ** 2)``)."""
    whole = (int, np.integer)
    if isinstance(a, whole) and isinstance(b, whole) and not isinstance(a, bool) and not isinstance(b, bool):
        a_, b_ = int(a), int(b)
        if b_ > 64 or (b_ > 0 and abs(a_).bit_length() * b_ > 31):
            raise OverflowError("a power of whole numbers too large to try as the `^`'s meaning")
    return a ** b


class _PowerForXor(ast.NodeTransformer):
    """`a ^ b` and `a ^= b` rewritten as a guarded `a ** b` (:func:`guarded_power`: `a = power(a, b)` for the
    statement; with ``drop``: as `a`, and the `a ^= b` statement left out), but not where b is a constant 0, 1, True
    or False; counts what it rewrote."""

    def __init__(self, drop: bool = False):
        self.count, self.drop = 0, drop

    @staticmethod
    def _power(left, right):
        return ast.Call(ast.Name(_GUARDED_POWER, ast.Load()), [left, right], [])

    def visit_BinOp(self, node):
        self.generic_visit(node)
        if isinstance(node.op, ast.BitXor) and not _identity_exponent(node.right):
            self.count += 1
            if self.drop:
                return node.left
            return ast.copy_location(self._power(node.left, node.right), node)
        return node

    def visit_AugAssign(self, node):
        self.generic_visit(node)
        if isinstance(node.op, ast.BitXor) and not _identity_exponent(node.value):
            self.count += 1
            if self.drop:
                return ast.copy_location(ast.Pass(), node)
            load = copy.deepcopy(node.target)
            load.ctx = ast.Load()
            return ast.copy_location(ast.Assign([node.target], self._power(load, node.value)), node)
        return node


def recompiled(fn: Callable, transformer: ast.NodeTransformer, cells: dict | None = None) -> Callable | None:
    """``fn`` with its source's tree changed by ``transformer``, compiled again with ``fn``'s globals, closure and
    defaults, and ``cells`` (name: value) as further closure variables (the learner's globals are not touched);
    None where it cannot be (no source, not a def, a closure that does not match)."""
    tree = _tree(fn)
    if tree is None or not tree.body or not isinstance(tree.body[0], ast.FunctionDef):
        return None
    f = _own(fn)
    if not isinstance(f, types.FunctionType):     # a cache's wrapper, a builtin: nothing to compile again
        return None
    fdef = tree.body[0]
    fdef.decorator_list = []
    fdef = transformer.visit(fdef)
    extra = dict(cells or {})
    free = tuple(f.__code__.co_freevars) + tuple(v for v in extra if v not in f.__code__.co_freevars)
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
        bound = dict(zip(f.__code__.co_freevars, f.__closure__ or ()))
        bound.update({name: types.CellType(value) for name, value in extra.items()})
        closure = tuple(bound[v] for v in inner.co_freevars) or None
        new = types.FunctionType(inner, f.__globals__, f.__name__, f.__defaults__, closure)
    except (KeyError, TypeError, ValueError):
        return None
    new.__kwdefaults__ = f.__kwdefaults__
    return new


def xor_power_hint(fn: Callable, err: BaseException | None = None, ex=None, case: tuple | None = None,
                   expected=None, call_as: Callable | None = None) -> str | None:
    """:data:`XOR_HINT` where ``^`` stands for a power: the error ``err`` is numpy's or torch's refusal of `^` on
    floats, or ``fn`` with its `^` rewritten as `**` (a constant 0, 1, True or False after it left alone: `x ** 1`
    is x) matches the reference (``expected``; run here where None) on ``case`` of exercise ``ex`` while ``fn``
    with that `^ b` removed does not, each called as the check calls ``fn`` (``call_as``: the notebook's form,
    :func:`.signature.called_the_same_way`); else None."""
    if err is not None and any(w in str(err) for w in XOR_ERROR_WORDS):
        return XOR_HINT
    if ex is None or case is None:
        return None
    rewrite = _PowerForXor()
    power = recompiled(fn, rewrite, {_GUARDED_POWER: guarded_power})
    if power is None or not rewrite.count:
        return None
    try:                # the reference's answer once, for both proofs
        expected = run(ex.reference, case[0], case[1], ex.observe) if expected is None else expected
    except Exception:
        return None
    if not _matches_reference(power, ex, case, expected, call_as):
        return None
    dropped = recompiled(fn, _PowerForXor(drop=True))
    if dropped is not None and _matches_reference(dropped, ex, case, expected, call_as):
        return None             # `^ b` left out matches as well: the power is not what made the difference
    return XOR_HINT


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
