"""A phsplit vessel as an FMI 2.0 co-simulation FMU, for FMPy, OSP's libcosim and every FMI host
(docs/fmu.md).

:func:`export` writes ``vessel.fmu``: ``modelDescription.xml``, the binary built from the Rust core
(``binaries/linux64/phsplit_fmu.so``, no Python inside) and the vessel and settings as resources.
The variable table comes from the same Rust code the binary serves (``phsplit-fmu``), so the two
cannot disagree. :func:`export_load` writes a second, small FMU from the same binary: a periodic
load source (a slowly varying pipe tension or wind load) to couple with a vessel.

Energy statement: the FMU integrates the vessel with the chosen method between communication
points, with the inputs held constant over each communication step (a zero-order hold, as every
co-simulation master gives them). Over one communication step the split keeps its guarantee
(exact passivity for positive-coefficient methods, Prop. 2.5's condition otherwise) with respect
to the constant inputs, and the outputs ``ledger.*`` book each port's work exactly as
:func:`phsplit.simulate` does. The coupling itself (what the master does between steps) is outside
the FMU and can create energy; the ledger shows what came in through ``external``.
"""
from __future__ import annotations

import hashlib
import io
import os
import platform
import sys
import tempfile
import uuid
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from . import _core

#: The model identifier: the binary's file name in ``binaries/<platform>/``.
MODEL_IDENTIFIER = "phsplit_fmu"

#: Where the package keeps the binaries it ships (built by ``make build``).
BINARIES = Path(__file__).parent / "_fmu" / "binaries"

#: Units of the variables, as SI base-unit exponents (FMI 2.0 ``UnitDefinitions``).
_UNITS = {
    "m": {"m": 1}, "rad": {"rad": 1}, "1": {}, "s": {"s": 1},
    "m/s": {"m": 1, "s": -1}, "rad/s": {"rad": 1, "s": -1},
    "N": {"kg": 1, "m": 1, "s": -2}, "N.m": {"kg": 1, "m": 2, "s": -2},
    "J": {"kg": 1, "m": 2, "s": -2}, "deg": {"rad": 1, "factor": 0.017453292519943295},
}


#: SI symbols as base-unit exponents, for units written as products of powers (CF/UDUNITS style:
#: ``kg m2 s-1``, ``N.m``, ``m/s``), the form components and subsystems give their outputs in.
_SYMBOLS = {"m": {"m": 1}, "kg": {"kg": 1}, "s": {"s": 1}, "rad": {"rad": 1}, "K": {"K": 1}, "A": {"A": 1},
            "N": {"kg": 1, "m": 1, "s": -2}, "J": {"kg": 1, "m": 2, "s": -2}, "W": {"kg": 1, "m": 2, "s": -3},
            "Pa": {"kg": 1, "m": -1, "s": -2}}


def _base_unit(u: str) -> dict | None:
    """The FMI ``BaseUnit`` of a unit: from the table above, or parsed as a product of SI symbols
    with integer powers (``/`` starts the denominator); ``None`` when it is not one (the unit is
    then declared by name only, which FMI 2.0 allows)."""
    if u in _UNITS:
        return _UNITS[u]
    import re

    out: dict[str, int] = {}
    num, _, den = u.partition("/")
    for sign, part in ((1, num), (-1, den)):
        for tok in part.replace(".", " ").replace("*", " ").split():
            m = re.fullmatch(r"([A-Za-z]+)\^?(-?\d+)?", tok)
            if tok == "1":
                continue
            if not m or m.group(1) not in _SYMBOLS:
                return None
            p = sign * int(m.group(2) or 1)
            for k, e in _SYMBOLS[m.group(1)].items():
                out[k] = out.get(k, 0) + e * p
    return {k: e for k, e in out.items() if e}


def _host_platform() -> str:
    """The FMI platform folder of this machine (linux64, win64, darwin64)."""
    bits = "64" if sys.maxsize > 2**32 else "32"
    system = {"linux": "linux", "win32": "win", "darwin": "darwin"}.get(sys.platform, sys.platform)
    return f"{system}{bits}"


def _binary_name(plat: str) -> str:
    ext = ".dll" if plat.startswith("win") else ".dylib" if plat.startswith("darwin") else ".so"
    return MODEL_IDENTIFIER + ext


#: What a shared library of each FMI platform is: its format and word size.
_FORMATS = {"linux64": ("an ELF shared object", 64), "linux32": ("an ELF shared object", 32),
            "win64": ("a Windows DLL (PE)", 64), "win32": ("a Windows DLL (PE)", 32),
            "darwin64": ("a Mach-O dynamic library", 64)}


def binary_problem(plat: str, data: bytes) -> str | None:
    """Why ``data`` is not an FMU binary for FMI platform ``plat`` (``None`` if it is one): the
    executable format and word size of the platform's shared libraries (ELF, PE, Mach-O, read
    from the file's header) and the FMI 2.0 entry point ``fmi2Instantiate`` among its symbols."""
    import struct

    what, bits = _FORMATS[plat]
    kind = None
    if data[:4] == b"\x7fELF" and len(data) > 18:
        cls = {1: 32, 2: 64}.get(data[4])
        endian = "<" if data[5] == 1 else ">"
        e_type = struct.unpack(endian + "H", data[16:18])[0]
        kind = ("an ELF shared object" if e_type == 3 else "an ELF file that is not a shared object", cls)
    elif data[:2] == b"MZ" and len(data) >= 64:
        off = struct.unpack("<I", data[60:64])[0]
        if data[off:off + 4] == b"PE\0\0" and len(data) >= off + 24:
            machine, = struct.unpack("<H", data[off + 4:off + 6])
            chars, = struct.unpack("<H", data[off + 22:off + 24])
            cls = {0x8664: 64, 0xAA64: 64, 0x14C: 32}.get(machine)
            kind = ("a Windows DLL (PE)" if chars & 0x2000 else "a Windows program (PE) that is not a DLL", cls)
    elif data[:4] in (b"\xcf\xfa\xed\xfe", b"\xce\xfa\xed\xfe") and len(data) >= 16:
        filetype, = struct.unpack("<I", data[12:16])
        kind = ("a Mach-O dynamic library" if filetype in (6, 8) else "a Mach-O file that is not a library",
                64 if data[0] == 0xCF else 32)
    elif data[:4] == b"\xca\xfe\xba\xbe":
        kind = ("a Mach-O dynamic library", 64)  # a universal binary: its slices hold the word size
    if kind is None:
        return f"is not a shared library (not ELF, PE or Mach-O); a {plat} FMU binary must be {what}, {bits}-bit"
    if kind[0] != what or kind[1] != bits:
        size = f"{kind[1]}-bit " if kind[1] else ""
        return f"is {size}{kind[0]}; a {plat} FMU binary must be {what}, {bits}-bit"
    if b"fmi2Instantiate" not in data:
        return "does not export the FMI 2.0 functions (no fmi2Instantiate in it): it is not an FMU binary"
    return None


def check_out(out: Any) -> Path:
    """Where an FMU is written, checked before it is built: a path (str or os.PathLike) that is not
    a folder and whose nearest existing ancestor is a folder (the missing ones are made)."""
    if not isinstance(out, (str, os.PathLike)) or not os.fspath(out):
        raise _core.InvalidInputError(f"out must be the .fmu file's path, got {out!r}")
    p = Path(out)
    if p.is_dir():
        raise _core.InvalidInputError(f"out {os.fspath(out)!r} is a folder; name the .fmu file to write")
    parent = p.absolute().parent
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise _core.InvalidInputError(f"out {os.fspath(out)!r} cannot be written: {os.fspath(parent)!r} is a file, "
                                      f"not a folder")
    return p


def _binaries(extra: Mapping[str, str | os.PathLike[str]] | None) -> dict[str, bytes]:
    """The binaries to pack: the shipped one for this machine, plus ``extra`` (platform -> path)."""
    if extra is not None and (not isinstance(extra, Mapping) or not all(
            isinstance(v, (str, os.PathLike)) for v in extra.values())):
        raise _core.InvalidInputError(f"binaries must be a mapping from platform to a binary's path, e.g. "
                                      f"{{'win64': 'phsplit_fmu.dll'}} (the CLI's --binary win64=PATH), got {extra!r}")
    out: dict[str, bytes] = {}
    plat = _host_platform()
    shipped = BINARIES / plat / _binary_name(plat)
    if shipped.exists():
        out[plat] = shipped.read_bytes()
    for p, path in (extra or {}).items():
        if p not in ("linux64", "linux32", "win64", "win32", "darwin64"):
            raise _core.InvalidInputError(f"binary platform must be one of linux64, linux32, win64, win32, "
                                          f"darwin64 (FMI 2.0 platform folders), got {p!r}")
        if os.path.isdir(path):
            raise _core.InvalidInputError(f"the {p} binary {os.fspath(path)!r} is a folder, not a shared library")
        try:
            data = Path(path).read_bytes()
        except OSError as e:
            raise _core.InvalidInputError(f"cannot read the {p} binary {os.fspath(path)!r}: {e.strerror}") from None
        why = binary_problem(p, data)
        if why:
            raise _core.InvalidInputError(f"the {p} binary {os.fspath(path)!r} {why}")
        out[p] = data
    if not out:
        raise _core.PhsplitError(
            f"no FMU binary for this platform ({plat}, {platform.machine()}): the package ships "
            f"{sorted(q.name for q in BINARIES.iterdir()) if BINARIES.exists() else 'none'}; build one with "
            "'cargo build -p phsplit-fmu --release' and pass it as binaries={'<platform>': path} "
            "(docs/fmu.md)")
    return out


def _toml(tables: Mapping[str, Any]) -> str:
    return _core.dumps_toml(dict(tables))


def _scalar_text(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v)
    return str(v)


def _model_description(name: str, description: str, variables: list[dict[str, Any]], guid: str,
                       experiment: Mapping[str, float]) -> bytes:
    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "2.0", "modelName": name, "guid": guid, "description": description,
        "generationTool": f"phsplit {_core.__version__}", "variableNamingConvention": "flat",
        "numberOfEventIndicators": "0",
    })
    ET.SubElement(root, "CoSimulation", {
        "modelIdentifier": MODEL_IDENTIFIER, "needsExecutionTool": "false",
        "canHandleVariableCommunicationStepSize": "true", "canInterpolateInputs": "false",
        "maxOutputDerivativeOrder": "0", "canRunAsynchronuously": "false",
        "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions": "true",
        "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "false",
        "providesDirectionalDerivative": "false",
    })
    used = sorted({v["unit"] for v in variables if v["unit"]})
    if used:
        units = ET.SubElement(root, "UnitDefinitions")
        for u in used:
            el = ET.SubElement(units, "Unit", {"name": u})
            base = _base_unit(u)
            if base is not None:
                ET.SubElement(el, "BaseUnit", {k: str(e) for k, e in base.items()})
    ET.SubElement(root, "DefaultExperiment", {k: repr(float(v)) for k, v in experiment.items()})
    mv = ET.SubElement(root, "ModelVariables")
    outputs = []
    for i, v in enumerate(variables, start=1):
        attrs = {"name": v["name"], "valueReference": str(v["vr"]), "description": v["description"],
                 "causality": v["causality"]}
        if v["causality"] == "parameter":
            attrs["variability"] = "fixed"
            attrs["initial"] = "exact"
        elif v["causality"] == "input":
            attrs["variability"] = "continuous" if v["type"] == "Real" else "discrete"
        else:
            attrs["variability"] = "continuous"
            attrs["initial"] = "calculated"
            outputs.append(i)
        sv = ET.SubElement(mv, "ScalarVariable", attrs)
        tattrs = {}
        if v["start"] is not None:
            tattrs["start"] = _scalar_text(v["start"])
        if v["unit"] and v["type"] == "Real":
            tattrs["unit"] = v["unit"]
        ET.SubElement(sv, v["type"], tattrs)
    ms = ET.SubElement(root, "ModelStructure")
    outs = ET.SubElement(ms, "Outputs")
    for i in outputs:
        ET.SubElement(outs, "Unknown", {"index": str(i)})
    init = ET.SubElement(ms, "InitialUnknowns")
    for i in outputs:
        ET.SubElement(init, "Unknown", {"index": str(i)})
    ET.indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8") + b"\n"


def _write_fmu(out: str | os.PathLike[str], name: str, description: str, resources: dict[str, str],
               experiment: Mapping[str, float], binaries: dict[str, bytes]) -> Path:
    """Pack an FMU: a GUID from the content, entries in a fixed order with fixed dates (the same
    inputs give the same bytes), written under a temporary name and renamed (no partial file)."""
    variables = _core.fmu_variables(resources["fmu.toml"], resources.get("vessel.toml"))
    digest = hashlib.sha256()
    for k in sorted(resources):
        digest.update(k.encode() + b"\0" + resources[k].encode() + b"\0")
    for p in sorted(binaries):
        digest.update(p.encode() + b"\0" + binaries[p] + b"\0")
    guid = "{" + str(uuid.UUID(bytes=digest.digest()[:16], version=4)) + "}"
    fmu_toml = resources["fmu.toml"].replace("[fmu]\n", f'[fmu]\nguid = "{guid}"\n', 1)
    md = _model_description(name, description, variables, guid, experiment)
    entries: list[tuple[str, bytes, int]] = [("modelDescription.xml", md, 0o644)]
    for p in sorted(binaries):
        entries.append((f"binaries/{p}/{_binary_name(p)}", binaries[p], 0o755))
    entries.append(("resources/fmu.toml", fmu_toml.encode(), 0o644))
    for k in sorted(resources):
        if k != "fmu.toml":
            entries.append((f"resources/{k}", resources[k].encode(), 0o644))
    out = Path(out)
    if out.suffix != ".fmu":
        raise _core.InvalidInputError(f"the FMU file must end in .fmu, got {os.fspath(out)!r}")
    out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{out.name}.", suffix=".tmp", dir=out.parent)
    try:
        with os.fdopen(fd, "wb") as f, zipfile.ZipFile(f, "w", zipfile.ZIP_DEFLATED) as z:
            for arc, data, mode in entries:
                info = zipfile.ZipInfo(arc, date_time=(1980, 1, 1, 0, 0, 0))
                info.external_attr = (0o100000 | mode) << 16
                info.compress_type = zipfile.ZIP_DEFLATED
                z.writestr(info, data)
        # mkstemp made the file private (0600); an FMU is for others to read, as any file made
        # under the user's umask.
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, out)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    return out


def export(scenario: Any = None, out: str | os.PathLike[str] = "vessel.fmu", *,
           binaries: Mapping[str, str | os.PathLike[str]] | None = None,
           model_name: str | None = None) -> Path:
    """Write a co-simulation FMU of a scenario's vessel and settings.

    ``scenario``: a :class:`phsplit.scenario.Scenario`, a scenario file or shipped scenario name,
    or None for the paper's Fig. 2 (the paper's vessel, SP4 at h = 0.5 s, the controller from
    t = 50 s). The FMU's parameters start at the scenario's values: ``method``, ``h`` (the internal
    step), ``linear_flow``, ``outer``, ``control``/``control_start``, ``project_invariants``,
    ``external_frame``, and every number of the vessel file (``vessel.mass``,
    ``initial.euler[0]``, …). Its inputs are the external force and moment, the set point
    (position and heading) and the current; its outputs the position, Euler angles, quaternion,
    body velocities, the controller's force and moment, the stored energy and the ledger by port.
    ``binaries`` adds binaries built for other platforms (``{"win64": "phsplit_fmu.dll"}``).
    ``out``: the ``.fmu`` file to write (its missing folders are made); ``model_name``: the FMU's
    name (default ``phsplit vessel (<scenario>)``), a non-empty string.

    >>> import phsplit.fmu, tempfile, os
    >>> path = phsplit.fmu.export(None, os.path.join(tempfile.mkdtemp(), "fig2.fmu"))
    >>> path.name
    'fig2.fmu'
    """
    from . import scenario as sc

    check_out(out)
    if model_name is not None and (not isinstance(model_name, str) or not model_name.strip()):
        raise _core.InvalidInputError(f"model_name must be a non-empty string (the FMU's name), or None for "
                                      f"phsplit's, got {model_name!r}")
    if scenario is None:
        s = sc.Scenario.paper_fig2()
    elif isinstance(scenario, sc.Scenario):
        s = scenario
    elif isinstance(scenario, (str, os.PathLike)):
        s = sc.load(sc.resolve(scenario))
    else:
        raise _core.InvalidInputError(
            f"export's scenario must be a phsplit.scenario.Scenario, a scenario file or a shipped scenario's name, "
            f"or None for the paper's Fig. 2; got {type(scenario).__name__} (a Vessel goes in as "
            f"phsplit.scenario.Scenario(vessel, settings))")
    st = s.settings
    if st.adaptive:
        raise _core.InvalidInputError(
            "the FMU steps with its fixed internal step h within each communication step; the scenario asks for "
            "adaptive steps (rtol, atol): drop rtol and atol (and h_max) from its [simulation] to export it")
    sim = {"method": st.method, "h": float(st.h), "linear_flow": st.linear_flow, "outer": st.outer,
           "project_invariants": bool(st.project_invariants),
           "control_start": "never" if st.control_start is None else float(st.control_start)}
    resources = {
        "fmu.toml": "[fmu]\nkind = \"vessel\"\n\n" + _toml({"simulation": sim}),
        "vessel.toml": s.vessel.to_toml(),
    }
    t0, t1 = st.t_span
    name = model_name or f"phsplit vessel ({s.name})"
    desc = (f"phsplit vessel '{s.name}' ({s.vessel.source or 'custom'}) integrated by passivity-preserving "
            "splitting (Celledoni, Hoiseth, Ramzina 2018); inputs: external load, set point, current")
    return _write_fmu(out, name, desc, resources, {"startTime": t0, "stopTime": t1, "stepSize": st.h},
                      _binaries(binaries))


def _real(v: Any) -> bool:
    """A real number given as one (not a string, not a boolean)."""
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))


def _vec3(name: str, v: Sequence[float]) -> list[float]:
    try:
        if isinstance(v, (str, bytes)) or not all(_real(x) for x in v):
            raise TypeError
        out = [float(x) for x in v]
    except (TypeError, ValueError):
        raise _core.InvalidInputError(f"{name} must be 3 numbers, got {v!r}") from None
    if len(out) != 3 or not all(x == x and abs(x) != float("inf") for x in out):
        raise _core.InvalidInputError(f"{name} must be 3 finite numbers, got {v!r}")
    limit = LOAD_LIMIT[name.split("_")[0]]
    if max(abs(x) for x in out) > limit:
        raise _core.InvalidInputError(f"{name} must lie within ±{limit:g} ({'N' if name.startswith('force') else 'N m'}; "
                                      f"no environment or actuator loads a vessel with more), got {v!r}")
    return out


#: The largest load the periodic source gives (10 GN, 10 TN m: beyond any vessel's loads).
LOAD_LIMIT = {"force": 1e10, "moment": 1e13}


def export_load(out: str | os.PathLike[str] = "load.fmu", *, force_mean: Sequence[float] = (0, 0, 0),
                force_amplitude: Sequence[float] = (0, 0, 0), moment_mean: Sequence[float] = (0, 0, 0),
                moment_amplitude: Sequence[float] = (0, 0, 0), period: float = 60.0,
                binaries: Mapping[str, str | os.PathLike[str]] | None = None) -> Path:
    """Write a periodic load source FMU: outputs ``force.x/y/z`` (N) and ``moment.x/y/z`` (N m),
    ``mean + amplitude · sin(2π t / period)`` per component, at each communication point; the
    means, amplitudes and period are its parameters. Connect its outputs to a vessel FMU's
    ``external_force.*`` and ``external_moment.*`` (see docs/fmu.md for an OSP system structure).
    """
    check_out(out)
    load = {"force_mean": _vec3("force_mean", force_mean),
            "force_amplitude": _vec3("force_amplitude", force_amplitude),
            "moment_mean": _vec3("moment_mean", moment_mean),
            "moment_amplitude": _vec3("moment_amplitude", moment_amplitude)}
    if not _real(period):
        raise _core.InvalidInputError(f"period must be a number of seconds, got {period!r}")
    p = float(period)
    if not (1e-3 <= p <= 1e7):
        raise _core.InvalidInputError(f"period must be a time in [1e-3, 1e7] s (a load varying faster than a "
                                      f"millisecond is no vessel's), got {period!r}")
    load["period"] = p
    resources = {"fmu.toml": "[fmu]\nkind = \"load\"\n\n" + _toml({"load": load})}
    return _write_fmu(out, "phsplit periodic load", "a periodic force and moment: mean + amplitude sin(2 pi t / period)",
                      resources, {"startTime": 0.0, "stepSize": 1.0}, _binaries(binaries))
