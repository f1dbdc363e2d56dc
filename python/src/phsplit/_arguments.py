"""The arguments of the public functions, checked before the function runs: an unknown
keyword, a missing or a surplus argument raise :class:`phsplit.InvalidInputError` naming the
argument and the function's arguments, instead of Python's ``TypeError`` from the call."""
from __future__ import annotations

import difflib
import functools
import inspect
from typing import Any, Callable, TypeVar

from . import _core

F = TypeVar("F", bound=Callable[..., Any])


def _names(sig: inspect.Signature) -> list[str]:
    return [p.name for p in sig.parameters.values()
            if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and not p.name.startswith("_") and p.name != "self"]


def explain(name: str, sig: inspect.Signature, args: tuple, kw: dict, error: TypeError) -> str:
    """One line saying what is wrong with a call of ``name`` and which arguments it takes."""
    names = _names(sig)
    takes = f"its arguments are {', '.join(names)}" if names else "it takes no argument"
    if not any(p.kind == p.VAR_KEYWORD for p in sig.parameters.values()):
        unknown = [k for k in kw if k not in sig.parameters or sig.parameters[k].kind == inspect.Parameter.POSITIONAL_ONLY]
        if unknown:
            k = unknown[0]
            close = difflib.get_close_matches(k, names, n=1)
            hint = f" (did you mean {close[0]}?)" if close else ""
            return f"{name}() has no argument {k!r}{hint}: {takes}"
    return f"{name}(): {error}; {takes}"


def _binds(sig: inspect.Signature) -> Callable[[tuple, dict], bool]:
    """A quick test that a call's arguments bind to ``sig``, for the common calls: True only
    where ``sig.bind`` would succeed (a call it cannot vouch for, ``False``, is bound by
    ``sig.bind``, which then names what is wrong). It spares each call ``inspect``'s binding
    (tens of microseconds, a share of a short run's time)."""
    P = inspect.Parameter
    ps = list(sig.parameters.values())
    if any(p.kind in (P.VAR_POSITIONAL, P.VAR_KEYWORD, P.POSITIONAL_ONLY) for p in ps):
        return lambda args, kw: False
    positional = [p.name for p in ps if p.kind == P.POSITIONAL_OR_KEYWORD]
    names = frozenset(p.name for p in ps)
    required = [(i, p.name) for i, p in enumerate(ps) if p.default is P.empty]

    def binds(args: tuple, kw: dict) -> bool:
        n = len(args)
        if n > len(positional) or not names.issuperset(kw):
            return False
        if any(k in kw for k in positional[:n]):
            return False  # one argument given twice
        return all(i < n or k in kw for i, k in required)

    return binds


def checked(f: F, name: str | None = None) -> F:
    """``f`` with its call's arguments bound to its signature first (see the module's text);
    ``name``: how the messages call it (default its qualified name)."""
    sig = inspect.signature(f)
    name = name or f.__qualname__
    binds = _binds(sig)

    @functools.wraps(f)
    def call(*args: Any, **kw: Any) -> Any:
        if not binds(args, kw):
            try:
                sig.bind(*args, **kw)
            except TypeError as e:
                raise _core.InvalidInputError(explain(name, sig, args, kw, e)) from None
        return f(*args, **kw)

    return call  # type: ignore[return-value]
