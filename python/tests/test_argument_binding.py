"""The quick test of a call's arguments (``phsplit._arguments._binds``) vouches only for calls
that ``inspect.Signature.bind`` accepts: checked against ``bind`` itself on every call shape of a
few signatures (positional, keyword-only, required, defaults, a given-twice argument)."""
import inspect
import itertools

import pytest

from phsplit import _arguments


def f1(a, b=1, *, c=2, d): ...
def f2(self, x, y=0): ...
def f3(*, only=1): ...
def f4(a, *rest, **kw): ...  # var arguments: never vouched for, bind decides


@pytest.mark.parametrize("f", [f1, f2, f3, f4])
def test_the_quick_test_vouches_only_for_calls_that_bind(f):
    sig = inspect.signature(f)
    quick = _arguments._binds(sig)
    names = ["a", "b", "c", "d", "self", "x", "y", "only", "zzz"]
    vouched = bound = 0
    for n in range(5):
        for kws in itertools.chain.from_iterable(itertools.combinations(names, k) for k in range(4)):
            args, kw = tuple(range(n)), {k: 0 for k in kws}
            try:
                sig.bind(*args, **kw)
                ok = True
            except TypeError:
                ok = False
            bound += ok
            if quick(args, kw):
                vouched += 1
                assert ok, (f.__name__, args, kw)
    # It is not vacuous: it vouches for most calls that bind (all but those of var arguments).
    assert bound > 0
    assert (vouched == 0) == (f is f4)
    if f is not f4:
        assert vouched == bound
