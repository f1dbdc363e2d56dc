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


def checked(f: F, name: str | None = None) -> F:
    """``f`` with its call's arguments bound to its signature first (see the module's text);
    ``name``: how the messages call it (default its qualified name)."""
    sig = inspect.signature(f)
    name = name or f.__qualname__

    @functools.wraps(f)
    def call(*args: Any, **kw: Any) -> Any:
        try:
            sig.bind(*args, **kw)
        except TypeError as e:
            raise _core.InvalidInputError(explain(name, sig, args, kw, e)) from None
        return f(*args, **kw)

    return call  # type: ignore[return-value]
