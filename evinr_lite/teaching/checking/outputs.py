"""Comparing a learner's output with the reference's, and describing values in a report.

:func:`compare_outputs` walks the two outputs together (tuples, lists, dicts, arrays, tensors, plain values) and
returns the first :class:`Problem`: a missing ``return``, a wrong type (an array subclass such as np.matrix, a lazy
iterator, an array of Python objects), shape or dtype (a tensor's float width too: torch does not convert between
float32 and float64 in a layer), with a word on the likely cause, or wrong values (how many, where, by how much). It is the one built-in yardstick every other module of the
check uses: the main run, the hints' wrong versions, the second call (an exercise may bring its own ``compare``,
which the main run and the second call use in its place). Where the values match and the reference's result is a
differentiable tensor, :func:`compare_gradients` compares what back-propagation from it reaches: a result rebuilt
as a new leaf, a term taken out of the graph, or a function that calls .backward() itself has the right values and
the wrong gradients. The helpers that read a tensor as numpy live here too, since every comparison starts with them.
"""
from __future__ import annotations

import sys
from dataclasses import dataclass

import numpy as np


def input_name(k: int) -> str:
    """How a report names the positional input ``k`` (from 0): "argument 1", "argument 2", ..."""
    return f"argument {k + 1}"


def named_inputs(args, kwargs: dict) -> list:
    """(name, value) for every input of a call: the positional ones by :func:`input_name`, then the keywords."""
    return [(input_name(k), a) for k, a in enumerate(args)] + list(kwargs.items())


def is_tensor(x) -> bool:
    return type(x).__module__.startswith("torch") and hasattr(x, "detach")


def to_numpy(x):
    if is_tensor(x):
        x = x.detach().cpu()
        return (x.float() if str(x.dtype) == "torch.bfloat16" else x).numpy()   # numpy has no bfloat16
    return np.asarray(x)


def not_finite(v) -> bool:
    """Some NaN or infinity in an output (in a tuple, list or dict of them too). A wrong version's NaN that meets
    the learner's NaN says little: many mistakes overflow alike."""
    if isinstance(v, dict):
        return any(not_finite(x) for x in v.values())
    if isinstance(v, (tuple, list)):
        return any(not_finite(x) for x in v)
    try:
        a = to_numpy(v)
        return a.dtype.kind in "fc" and not bool(np.all(np.isfinite(a)))
    except Exception:
        return False


def _is_bfloat16(x) -> bool:
    return is_tensor(x) and str(x.dtype) == "torch.bfloat16"


def _fmt(v) -> str:
    if isinstance(v, (float, np.floating)):
        return f"{float(v):.4g}"
    return str(v)


def _fmt_pair(a, b) -> tuple[str, str]:
    """Two numbers formatted so that they read differently when they differ (4 digits, more when needed)."""
    fa, fb = _fmt(a), _fmt(b)
    if fa == fb and isinstance(a, (float, np.floating)) and isinstance(b, (float, np.floating)) and a != b:
        return f"{float(a):.12g}", f"{float(b):.12g}"
    return fa, fb


def _describe_value(v) -> str:
    if not isinstance(v, (np.ndarray, np.generic, int, float, str, bool, list, tuple, dict)) and not is_tensor(v) \
            and v is not None and ("\n" in repr(v) or len(repr(v)) > 60):
        return type(v).__name__          # a model or an optimiser: its repr would fill the report
    if is_tensor(v):
        return f"tensor {str(v.dtype).replace('torch.', '')}{list(v.shape)}"
    if isinstance(v, np.ndarray):
        return f"{v.dtype}{list(v.shape)}" if v.size > 4 else np.array2string(v, precision=3)
    if isinstance(v, (list, tuple)) and len(v) > 4:
        return f"{type(v).__name__} of {len(v)}"
    if isinstance(v, dict) and len(repr(v)) > 60:          # a table of rows: its repr would fill the headline
        return f"dict of {len(v)} items ({', '.join(repr(k) for k in list(v)[:4])}{', ...' if len(v) > 4 else ''})"
    return _fmt(v) if isinstance(v, (int, float, np.number)) else repr(v)


def describe_case(args: tuple, kwargs: dict) -> str:
    parts = [_describe_value(a) for a in args] + [f"{k}={_describe_value(v)}" for k, v in kwargs.items()]
    return ", ".join(parts)


def _kind(a: np.ndarray) -> str:
    return {"b": "bool", "i": "integer", "u": "integer", "f": "float", "c": "complex"}.get(a.dtype.kind, str(a.dtype))


@dataclass
class Problem:
    message: str
    values: bool = False  # True when shapes/types agree and only the numbers differ


def first_difference(ex, got, expected) -> Problem | None:
    """The first difference between the learner's output and the reference's for exercise ``ex`` (an
    :class:`~.protocol.ExerciseLike`): by its own comparison (``ex.compare``) when it has one, else by
    :func:`compare_outputs` within its tolerances."""
    if ex.compare is None:
        return compare_outputs(got, expected, ex.rtol, ex.atol)
    try:
        msg = ex.compare(got, expected)
    except Exception as err:     # a return value the comparison cannot read at all
        msg = f"returned a {type(got).__name__} that cannot be compared ({type(err).__name__}: {err})"
    return None if msg is None else Problem(msg, values=True)


def compare_outputs(got, expected, rtol: float, atol: float, where: str = "") -> Problem | None:
    at = f" in output {where}" if where else ""
    if got is None and expected is not None:
        return Problem(f"returned None{at}; did you forget the `return` statement?")
    if isinstance(expected, (tuple, list)):
        if not isinstance(got, (tuple, list)):
            return Problem(f"returned a {type(got).__name__}{at}, expected a {type(expected).__name__} of {len(expected)} items")
        if len(got) != len(expected):
            return Problem(f"returned {len(got)} items{at}, expected {len(expected)}")
        for k, (g, e) in enumerate(zip(got, expected)):
            p = compare_outputs(g, e, rtol, atol, f"{where}[{k}]")
            if p is not None:
                return p
        return None
    if isinstance(expected, dict):
        if not isinstance(got, dict):
            return Problem(f"returned {type(got).__name__}{at}, expected a dict with keys {sorted(expected)}")
        if set(got) != set(expected):
            missing = sorted(set(expected) - set(got), key=str)
            extra = sorted(set(got) - set(expected), key=str)
            return Problem(f"returned a dict{at} with the wrong keys: missing {missing}, not expected {extra}; "
                            "use the input's keys unchanged (the same spelling and case)")
        for k in expected:
            p = compare_outputs(got[k], expected[k], rtol, atol, f"{where}[{k!r}]")
            if p is not None:
                return p
        return None
    if is_tensor(expected) and not is_tensor(got):
        if expected.is_floating_point():
            return Problem(f"returned a {type(got).__name__}{at}, expected a torch.Tensor: keep the computation "
                            "in torch so that it can be back-propagated")
        return Problem(f"returned a {type(got).__name__}{at}, expected a torch.Tensor like the input: use torch "
                        "operations on the tensor (no .numpy() or Python lists)")
    if is_tensor(expected) and expected.requires_grad and not got.requires_grad:
        return Problem(f"the result{at} is cut off from the autograd graph (it does not require grad): keep the "
                        "computation in torch operations on the inputs, without .item(), float(), .numpy(), "
                        ".detach() or torch.tensor(...) on an intermediate value, so that it can be back-propagated")
    if isinstance(expected, np.ndarray) and is_tensor(got):
        return Problem(f"returned a torch.Tensor{at}, expected a numpy array: compute with numpy, or convert "
                        "with `.detach().cpu().numpy()`")
    if type(expected) is np.ndarray and isinstance(got, np.ndarray) and type(got) is not np.ndarray:
        return Problem(_subclass_message(got, at))
    if isinstance(expected, np.ndarray) and isinstance(got, (list, tuple)):
        return Problem(f"returned a {type(got).__name__}{at}, expected a numpy array: return "
                        "`np.asarray(...)` of it (later cells use array methods such as .shape)")
    if isinstance(expected, (np.ndarray, np.generic, int, float, bool)) or is_tensor(expected):
        try:
            g = to_numpy(got)
        except Exception:
            return Problem(f"returned a {type(got).__name__}{at}, expected numbers")
        e = to_numpy(expected)
        if g.dtype == object or g.dtype.kind not in "biufc":
            return Problem(f"returned {type(got).__name__} of dtype {g.dtype}{at}, expected numbers"
                           + _object_note(got, g))
        if g.shape != e.shape:
            return Problem(f"wrong shape{at}: got {g.shape}, expected {e.shape}" + _shape_note(g, e))
        if _kind(g) != _kind(e):
            return Problem(f"wrong dtype{at}: got {_kind(g)} ({g.dtype}), expected {_kind(e)} ({e.dtype})"
                            + _dtype_note(g, e, rtol, atol, is_tensor(got)))
        width = _tensor_width_message(got, expected, at)
        if width:
            return Problem(width)
        close = np.isclose(g, e, rtol=rtol, atol=atol, equal_nan=True)
        if np.all(close):
            return None
        if g.dtype.kind == "u" and np.any(e < 0):
            return Problem(f"wrong values{at}: an unsigned dtype ({g.dtype}) cannot hold the negative values "
                            "expected (-1 wraps round to the largest value): use a signed integer dtype (np.int64)")
        if _is_bfloat16(got) and not _is_bfloat16(expected):
            return Problem(f"wrong values{at}: the result is bfloat16 (about 3 significant digits: `.bfloat16()`, "
                            "or torch.autocast), too coarse for these values: compute and return float32 like the "
                            "inputs")
        if g.dtype == np.float16 and e.dtype != np.float16:
            return Problem(f"wrong values{at}: the result is float16 (half precision, about 3 significant "
                            "digits), too coarse for these values: compute and return float64 (or float32)")
        if g.dtype == np.float32 and e.dtype == np.float64 and np.allclose(g, e, rtol=1e-3, atol=1e-6 + atol):
            return Problem(f"wrong values{at}: the result is float32 (about 7 significant digits) and differs from "
                            f"the expected float64 values in the last digits, beyond this exercise's tolerance "
                            f"(rtol {rtol:g}): compute in float64 (np.asarray(..., dtype=np.float64))")
        bad = np.flatnonzero(~close.ravel())
        diff = np.abs(g.astype(np.float64) - e.astype(np.float64)).ravel()
        diff = np.where(np.isnan(diff), np.inf, diff)
        worst = int(bad[np.argmax(diff[bad])])
        if e.ndim == 0:
            gs, es = _fmt_pair(g.item(), e.item())
            return Problem(f"wrong value{at}: got {gs}, expected {es}", values=True)
        idx = np.unravel_index(worst, e.shape)
        idx_s = str(idx[0]) if len(idx) == 1 else str(tuple(int(i) for i in idx))
        gs, es = _fmt_pair(g.ravel()[worst], e.ravel()[worst])
        return Problem(f"wrong values{at}: {bad.size} of {e.size} differ; at index {idx_s}: got {gs}, expected {es}",
                        values=True)
    # anything else: plain equality
    if got != expected:
        return Problem(f"got {got!r}{at}, expected {expected!r}", values=True)
    return None


def _subclass_message(got: np.ndarray, at: str) -> str:
    """A numpy array subclass (np.matrix, a masked array, ...) where the reference returns a plain array."""
    if isinstance(got, np.matrix):
        return (f"returned a numpy.matrix{at}, expected a plain numpy array: np.matrix (np.matrix(A), np.asmatrix, "
                "`.I`, `.H`) is deprecated and behaves otherwise: `*` is a matrix product, a row `W[0]` or "
                "`W.ravel()` stays 2-D; compute with arrays (`@`, np.linalg.solve, np.linalg.inv), or return "
                "np.asarray(...) of it")
    if isinstance(got, np.ma.MaskedArray):
        return (f"returned a masked array (np.ma){at}, expected a plain numpy array: later cells' sums and means "
                "skip its masked entries and its .data may hold anything there; compute the values themselves "
                "(np.where for a choice per entry), or return np.ma.filled(result, value) with the value the "
                "exercise asks for")
    return (f"returned a {type(got).__module__}.{type(got).__name__}{at} (a subclass of numpy's array), expected a "
            "plain numpy array: return np.asarray(...) of it")


def _object_note(got, g: np.ndarray) -> str:
    """A word on a result that holds no numbers: a lazy iterator (map, filter, zip, a generator), or an array of
    Python objects."""
    if hasattr(got, "__next__"):
        return (f": a {type(got).__name__} object is a lazy iterator, read once and then empty, not the values "
                "themselves; make an array of it: np.array(list(...)), or use numpy on the whole array "
                "(np.exp(L), not map(math.exp, L))")
    if isinstance(got, np.ndarray) and got.dtype == object:
        return (": an array of dtype object holds Python objects, one per entry (`.astype(object)`, np.array of "
                "a list that mixes arrays of different lengths, numbers and None, or of a list of tensors); "
                "build it with a numeric dtype (np.zeros(..., dtype=...), np.stack, np.concatenate)")
    return ""


def _tensor_width_message(got, expected, at: str) -> str | None:
    """A float32 tensor of values (one or more axes) where the reference's is float64, or the reverse: unlike numpy,
    torch does not convert for a matrix product or a layer (`expected scalar type Float but found Double`), so the
    width is part of the answer. bfloat16 and float16 keep their own words (after the values)."""
    if not (is_tensor(got) and is_tensor(expected)) or expected.dim() == 0:
        return None          # a loss (one number) may be float64: it feeds no layer, and backward() casts back
    widths = {"torch.float32": "float32", "torch.float64": "float64"}
    g, e = widths.get(str(got.dtype)), widths.get(str(expected.dtype))
    if g is None or e is None or g == e:
        return None
    how = ("a float64 tensor comes from numpy floats (torch.as_tensor / torch.from_numpy of a float64 array or of "
           "np.float64(omega)), torch.tensor of a float64 array, or .double()") if g == "float64" else \
        "a float32 tensor comes from torch.tensor(...) of Python floats, .float(), or torch.Tensor(...)"
    return (f"wrong dtype{at}: got a {g} tensor, expected {e} like the inputs: torch does not convert between them "
            f"in a matrix product or a layer (`expected scalar type Float but found Double`), so the next step "
            f"fails or a loss mixes widths; {how}: keep the inputs' dtype (torch.as_tensor(x, dtype=h.dtype), or "
            f"multiply by a Python float)")


# what `.T` does to a stack, and what to use instead: a shape note here, and hints.axes_order_hint
STACK_T_ADVICE = ("`.T` of an array with three or more axes reverses all of them, not only the last two; swap rows "
                  "and columns with np.swapaxes(a, -1, -2) (a.transpose(0, 2, 1)), or move one axis with np.moveaxis")


def _shape_note(g: np.ndarray, e: np.ndarray) -> str:
    """A word on a wrong shape that names a common cause: a transposed result, indices for a mask, an array
    holding one number where a number is expected."""
    if e.ndim >= 2 and g.ndim == e.ndim and g.shape[:-2] == e.shape[:-2] and g.shape[-2:] == e.shape[-2:][::-1]:
        return ("; the last two axes are swapped: a transposed result, or (H, W) read as (W, H) (sensor_size and "
                "images are rows first: `H, W = sensor_size`, `np.zeros((H, W))`, `a[y, x]`)")
    if e.ndim >= 3 and g.ndim == e.ndim and sorted(g.shape) == sorted(e.shape):
        return "; the same axes in another order: " + STACK_T_ADVICE
    if e.dtype == bool and g.dtype.kind in "iu" and g.size <= e.size:
        return ("; that looks like the indices of the True entries (np.flatnonzero, np.where, np.argwhere): "
                "return the boolean mask itself, one entry per element")
    if e.ndim == 1 and g.ndim == 1 and abs(g.shape[0] - e.shape[0]) == 1:
        more = "one entry too many" if g.shape[0] > e.shape[0] else "one entry too few"
        return f"; {more}: an off-by-one (a loop's range, a slice, or a count rounded the wrong way)?"
    if e.ndim >= 3 and g.ndim == e.ndim and g.shape[1:] == e.shape[1:] and abs(g.shape[0] - e.shape[0]) == 1:
        more = "one entry too many" if g.shape[0] > e.shape[0] else "one entry too few"
        return (f"; {more} along the first axis: an off-by-one (a loop's range, a slice, np.diff's `prepend=` "
                "that keeps the length: B + 1 boundaries make B bins)?")
    if e.ndim == 0 and g.size == 1:
        return ("; that is an array holding one number where the number itself is expected: take it out "
                "(`x[0]`, `x.squeeze()`, or `float(x)` for a numpy result), e.g. np.linalg.lstsq returns an array")
    if e.ndim == 0 and g.size > 1:
        return (f"; one number is expected, not {g.size}: reduce over every entry (np.mean(x) or torch.mean(x) "
                "without `axis=` / `dim=`), and return that number alone")
    if g.size == e.size and g.size > 1 and tuple(d for d in g.shape if d != 1) == tuple(d for d in e.shape if d != 1):
        return ("; the same number of entries with an extra or missing axis of length 1 (a column (N, 1) for a "
                "1-D (N,), say): drop `[:, None]` / `reshape(-1, 1)` / `keepdims=True`, or `.ravel()` the result")
    return ""


def _dtype_note(g: np.ndarray, e: np.ndarray, rtol: float = 1e-5, atol: float = 1e-8,
                tensor: bool = False) -> str:
    """A word on a wrong dtype that names a common cause (``rtol``, ``atol``: the exercise's tolerances, to tell
    whether a complex result's real part is the answer; ``tensor``: the result is a torch tensor)."""
    if e.dtype == bool and g.dtype.kind in "iuf":
        return ": return the comparison itself (a boolean mask), without .astype(int) or multiplying by 1"
    if e.dtype.kind in "iu" and g.dtype.kind == "f":
        return (": `/` (and np.trunc, np.floor, np.round) give floats: use integer division `//` "
                "(torch.div(..., rounding_mode='floor')), or convert with .astype(np.int64) after rounding; an "
                "array made without a dtype (np.zeros(n), np.full(n, p)) is float too: give dtype=")
    if e.dtype.kind == "f" and g.dtype.kind == "c":
        return _complex_note(g, e, rtol, atol, tensor)
    if e.dtype.kind == "f" and g.dtype.kind in "iu":
        return (": the values were made whole numbers: no .astype(int) or int(...) on the result, and no integer "
                "array to fill (np.zeros(..., dtype=int), or np.zeros_like of an integer input such as x or p)")
    return ""


def _complex_note(g: np.ndarray, e: np.ndarray, rtol: float, atol: float, tensor: bool) -> str:
    """A complex result where floats are expected: where complex numbers come from, and whether the real part is the
    answer. The imaginary parts count as about 0 where each is within the exercise's tolerance of 0 (``atol`` +
    ``rtol`` times the expected value); then the real part is compared as any result is, and what that comparison
    says is quoted, with no guess at its cause."""
    cause = (": complex numbers come from an FFT (np.fft.ifft, np.fft.ifft2), np.emath / np.lib.scimath, a power "
             "or root of a negative number (`(-x) ** 0.5`), or `+ 0j`")
    fix = "`.real`" if tensor else "`.real`, or np.real_if_close"
    imag = np.abs(g.imag)
    largest = float(np.max(imag)) if g.size else 0.0
    with np.errstate(invalid="ignore"):
        about_0 = bool(np.all(imag <= atol + rtol * np.abs(e.astype(np.float64))))
    if not about_0:
        return cause + (f"; the imaginary parts here reach {largest:.3g}, beyond this exercise's tolerance, so "
                        "`.real` alone would not fix the result: the computation itself differs")
    real = compare_outputs(g.real, e, rtol, atol)
    if real is None:
        return cause + (f"; the imaginary parts here are all about 0 (at most {largest:.2g}) and the real parts are "
                        f"the expected values: return the real part ({fix}) as a float array")
    return cause + (f"; the imaginary parts here are all about 0 (at most {largest:.2g}), and `.real` gives a "
                    f"float result, but it does not match either: {real.message}")


def differing_leaf(got, expected, rtol: float, atol: float):
    """The (got, expected) pair, inside nested tuples, lists and dicts, where the two first differ."""
    try:
        if isinstance(expected, (tuple, list)) and isinstance(got, (tuple, list)) and len(got) == len(expected):
            for g, e in zip(got, expected):
                if compare_outputs(g, e, rtol, atol) is not None:
                    return differing_leaf(g, e, rtol, atol)
        if isinstance(expected, dict) and isinstance(got, dict) and set(got) == set(expected):
            for k in expected:
                if compare_outputs(got[k], expected[k], rtol, atol) is not None:
                    return differing_leaf(got[k], expected[k], rtol, atol)
    except Exception:
        pass
    return got, expected


# ---- gradients: what back-propagation from a differentiable result reaches ----------------------------------

BACKWARD_CALLED = (
    "your function calls .backward() itself: the gradients land in the inputs' .grad at every call, and the "
    "caller's own loss.backward() then fails (the graph is freed) or, with retain_graph=True, adds them a second "
    "time; return the loss and leave back-propagation to the caller (the training step)")


def _tensor_pairs(got, expected) -> list | None:
    """(got, expected) for the tensors inside ``expected``, walking its structure: dict values by key, tuples and
    lists by position; None where ``got`` has another structure (another key set, another length, no tensor where
    ``expected`` holds one), so that nothing is compared out of place."""
    if isinstance(expected, dict):
        if not isinstance(got, dict) or set(got) != set(expected):
            return None
        parts = [_tensor_pairs(got[k], expected[k]) for k in expected]
    elif isinstance(expected, (tuple, list)):
        if not isinstance(got, (tuple, list)) or len(got) != len(expected):
            return None
        parts = [_tensor_pairs(g, e) for g, e in zip(got, expected)]
    elif is_tensor(expected):
        return [(got, expected)] if is_tensor(got) else None
    else:
        return []
    if any(p is None for p in parts):
        return None
    return [pair for p in parts for pair in p]


def _grad_inputs(inputs: tuple) -> list:
    """(name, tensor) for the inputs (args, kwargs) that are leaf tensors requiring grad."""
    return [(n, v) for n, v in named_inputs(*inputs) if is_tensor(v) and v.requires_grad and v.is_leaf]


def compare_gradients(got, got_inputs: tuple, expected, expected_inputs: tuple) -> Problem | None:
    """Whether back-propagation from ``got`` reaches the inputs as it does from ``expected`` (their values already
    match). ``got_inputs`` and ``expected_inputs``: the (args, kwargs) each run was given, as they are after it (the
    result's graph ends there). The outputs are weighted by fixed random numbers (a generator of its own: the global
    one is not touched) and summed, and the gradients of that sum with respect to every input that requires grad
    are compared (loosely: float32 sums in another order differ in their last digits). None when nothing is
    differentiable or all agree."""
    torch = sys.modules.get("torch")
    leaves = _tensor_pairs(got, expected)
    if torch is None or leaves is None or not any(e.requires_grad for _, e in leaves):
        return None
    named_got, named_exp = _grad_inputs(got_inputs), _grad_inputs(expected_inputs)
    if not named_exp or [n for n, _ in named_got] != [n for n, _ in named_exp]:
        return None
    if any(g.grad is not None and e.grad is None for (_, g), (_, e) in zip(named_got, named_exp)):
        return Problem(BACKWARD_CALLED)
    pairs = [(g, e) for g, e in leaves if e.requires_grad]
    inputs = [v for _, v in named_got]
    # a leaf that requires grad and is none of the inputs (an input handed back is compared by its gradients below)
    if any(e.grad_fn is not None and g.requires_grad and g.grad_fn is None and not any(g is v for v in inputs)
           for g, e in pairs):
        return Problem("the value is right, but the result is a new tensor with no autograd history "
                       "(torch.tensor(..., requires_grad=True), or .requires_grad_() on a value taken out of the "
                       "graph): it requires grad, yet back-propagation from it reaches none of the inputs, so "
                       "training would update nothing; compute it with torch operations on the inputs themselves "
                       "(no .item(), .numpy(), .detach() or torch.tensor(...) on the way)")
    gen = torch.Generator().manual_seed(0)
    weights = [torch.rand(e.shape, generator=gen, dtype=torch.float64) for _, e in pairs]

    def grads(leaves, inputs):
        total = sum((t * w.to(t.dtype)).sum() for t, w in zip(leaves, weights) if t.requires_grad)
        return torch.autograd.grad(total, [v for _, v in inputs], allow_unused=True)
    try:
        want = grads([e for _, e in pairs], named_exp)
    except Exception:            # the reference's own graph cannot say: say nothing
        return None
    try:
        have = grads([g for g, _ in pairs], named_got)
    except RuntimeError as err:
        if "second time" in str(err) or "freed" in str(err):
            return Problem(BACKWARD_CALLED)
        return Problem(f"the value is right, but it cannot be back-propagated ({err})")
    for (name, v), a, b in zip(named_got, have, want):
        a = np.zeros(tuple(v.shape)) if a is None else to_numpy(a).astype(np.float64)
        b = np.zeros(tuple(v.shape)) if b is None else to_numpy(b).astype(np.float64)
        scale = float(np.abs(b).max()) if b.size else 0.0
        close = np.isclose(a, b, rtol=1e-4, atol=1e-6 * scale + 1e-8)
        if np.all(close):
            continue
        out_of_graph = ("part of the computation uses a value taken out of the autograd graph (.detach(), .data, "
                        ".item(), .numpy(), torch.tensor(...)), so training would not update what "
                        f"`{name}` feeds; use the tensors themselves in every term")
        if not np.any(a) and np.any(b):
            return Problem(f"the value is right, but back-propagation from it does not reach `{name}`: "
                           + out_of_graph)
        worst = int(np.argmax(np.where(close, 0.0, np.abs(a - b)).ravel()))
        ga, gb = _fmt_pair(a.ravel()[worst], b.ravel()[worst])
        return Problem(f"the value is right, but its gradient with respect to `{name}` is not the reference's "
                       f"({int((~close).sum())} of {close.size} entries differ; at index {worst}: got {ga}, expected "
                       f"{gb}): " + out_of_graph)
    return None
