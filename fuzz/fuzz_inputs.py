#!/usr/bin/env python3
"""Coverage-guided fuzz target (atheris) for the input parsers: the vessel TOML parser (Rust,
through the binding) and the scenario loader (Python). Any exception other than the two
documented ones (ScenarioParseError, InvalidInputError), or a crash of the interpreter, is a bug.

Run: make fuzz   (or .venv/bin/python fuzz/fuzz_inputs.py -max_total_time=60 fuzz/corpus)
"""
import os
import sys
import tempfile

import atheris

with atheris.instrument_imports():
    import phsplit
    from phsplit import scenario as scn

ALLOWED = (phsplit.ScenarioParseError, phsplit.InvalidInputError)
TMP = tempfile.mkdtemp(prefix="phsplit-fuzz-")
PATH = os.path.join(TMP, "s.toml")


def one_input(data: bytes) -> None:
    fdp = atheris.FuzzedDataProvider(data)
    which = fdp.ConsumeIntInRange(0, 1)
    text = fdp.ConsumeUnicodeNoSurrogates(len(data))
    try:
        if which == 0:
            phsplit.Vessel.from_toml_str(text)
        else:
            with open(PATH, "w", encoding="utf-8") as f:
                f.write(text)
            scn.load(PATH)
    except ALLOWED:
        pass


if __name__ == "__main__":
    atheris.Setup(sys.argv, one_input)
    atheris.Fuzz()
