"""The runnable examples in the docstrings of the public numerics modules are run as tests, so
the documentation cannot drift from the code (issue 16)."""
from __future__ import annotations

import doctest

import pytest

import phsplit
from phsplit import events, results, rigid_body, so3, special


@pytest.mark.parametrize("module", [special, rigid_body, so3, results, events, phsplit], ids=lambda m: m.__name__)
def test_docstring_examples_run(module):
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    assert result.attempted > 0, f"{module.__name__} has no examples"
    assert result.failed == 0


@pytest.mark.parametrize(
    "func",
    [special.ellipj, special.ellipk, special.ellipkinc, special.ellipkm1, so3.exp, so3.log, so3.euler_zyx,
     so3.from_euler_zyx, so3.quaternion, so3.from_quaternion, rigid_body.FreeRigidBody.momentum,
     rigid_body.FreeRigidBody.flow, rigid_body.FreeRigidBody.period],
    ids=lambda f: f.__qualname__,
)
def test_every_public_function_has_an_example(func):
    assert ">>>" in (func.__doc__ or ""), f"{func.__qualname__} has no runnable example"
