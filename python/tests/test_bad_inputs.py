"""Every entry of the catalogue of bad inputs raises the stated error with a message that names
the offending field and what is allowed; the published catalogue (docs/errors.md) is current."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from bad_inputs import CATALOGUE

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def test_the_catalogue_is_large_enough():
    assert len(CATALOGUE) >= 230


@pytest.mark.parametrize("bad", CATALOGUE, ids=[b.what for b in CATALOGUE])
def test_bad_input_gets_a_clear_error(bad):
    with pytest.raises(bad.error) as info:
        bad.make()
    msg = str(info.value)
    for words in bad.must_say:
        assert words in msg, f"{bad.what}: {words!r} missing from: {msg}"
    assert "Traceback" not in msg and "panicked" not in msg
    # every mistake made through the API or a file is an InvalidInputError
    from bad_inputs import CliError

    import phsplit

    assert isinstance(info.value, (phsplit.InvalidInputError, CliError)), type(info.value)


def test_docs_catalogue_is_current():
    r = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "gen_error_catalogue.py"), "--check"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
