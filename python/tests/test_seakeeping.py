"""phsplit.rao (phsplit.seakeeping; docs/how-to/seakeeping-rao.md): the regular-wave response of
the paper's vessel with the fluid memory of the shipped box, in the time domain against the
frequency domain of the same dataset. The numbers are those of the table of
docs/explanation/components/fluid-memory.md; the bad arguments are refused in one line each,
naming the argument."""
from __future__ import annotations

import math

import numpy as np
import phsplit
import pytest
from phsplit import radiation, seakeeping

# The table of docs/explanation/components/fluid-memory.md ("The response to regular waves"):
# (heading, omega) -> {dof: (frequency domain, time domain)}, heave m/m, roll and pitch deg/m.
PAGE = {
    (90.0, 0.44): {"heave": (0.9996, 1.002), "roll": (1.925, 1.981)},
    (90.0, 0.56): {"heave": (0.9985, 0.9997), "roll": (20.02, 20.16)},
    (90.0, 0.68): {"heave": (1.014, 1.008), "roll": (2.16, 2.159)},
    (90.0, 1.04): {"heave": (0.8407, 0.8349), "roll": (0.1154, 0.1464)},
    (90.0, 1.40): {"heave": (0.1431, 0.1431), "roll": (0.3654, 0.369)},
    (180.0, 0.44): {"heave": (0.9163, 0.9182), "pitch": (1.075, 1.074)},
    (180.0, 0.56): {"heave": (0.7827, 0.7801), "pitch": (1.609, 1.605)},
    (180.0, 0.68): {"heave": (0.5504, 0.5471), "pitch": (2.046, 2.033)},
    (180.0, 1.04): {"heave": (0.1565, 0.1555), "pitch": (0.4158, 0.427)},
    (180.0, 1.40): {"heave": (0.02635, 0.02634), "pitch": (0.05925, 0.05933)},
}
OMEGAS = (0.44, 0.56, 0.68, 1.04, 1.40)


@pytest.fixture(scope="module")
def memory():
    return radiation.fluid_memory(seakeeping.DEFAULT_DATASET, vessel=phsplit.Vessel.paper())


@pytest.fixture(scope="module")
def raos(memory):
    paper = phsplit.Vessel.paper()
    return {beta: phsplit.rao(paper, OMEGAS, beta, fluid_memory=memory) for beta in (90.0, 180.0)}


def test_it_reproduces_the_fluid_memory_page_within_one_percent(raos):
    worst = 0.0
    for (beta, w), row in PAGE.items():
        ds = raos[beta].sel(frequency=w)
        for dof, (fd, td) in row.items():
            f = 1.0 if dof == "heave" else 180.0 / math.pi
            for got, want in ((f * float(ds[f"{dof}_amplitude_frequency_domain"]), fd),
                              (f * float(ds[f"{dof}_amplitude"]), td)):
                assert abs(got / want - 1) < 0.01, (beta, w, dof, got, want)
                worst = max(worst, abs(got / want - 1))
            assert math.isclose(float(ds[f"{dof}_deviation"]), td_fd := f * float(ds[f"{dof}_amplitude"]) /
                                (f * float(ds[f"{dof}_amplitude_frequency_domain"])) - 1, rel_tol=1e-12), td_fd
    assert worst < 0.01


def test_phases_agree_where_the_response_is_large_and_the_runs_close_their_ledger(raos):
    """Where the RAO is at least 5 % of its peak and within 5 % in amplitude, the time domain's
    phase against the wave elevation is within 0.15 rad of the frequency domain's."""
    for beta, ds in raos.items():
        assert ds.attrs["Conventions"] == "CF-1.8" and ds.attrs["heading"] == beta
        assert ds["frequency"].attrs["units"] == "rad s-1"
        assert ds["heave_amplitude"].attrs["units"] == "m m-1" and ds["roll_phase"].attrs["units"] == "rad"
        assert np.all(ds["ledger_residual"].values < 1e-10)
        assert np.all(ds["radiation_dissipated"].values > 0.0)
        for dof in ("heave", "roll", "pitch"):
            fd = ds[f"{dof}_amplitude_frequency_domain"].values
            if fd.max() < 1e-6:   # not excited at this heading (the hull's symmetry)
                continue
            ok = (fd >= 0.05 * fd.max()) & (np.abs(ds[f"{dof}_deviation"].values) < 0.05)
            d = np.angle(np.exp(1j * (ds[f"{dof}_phase"].values - ds[f"{dof}_phase_frequency_domain"].values)))
            assert ok.sum() >= 3 and np.all(np.abs(d[ok]) < 0.15), (beta, dof, d)


def test_without_the_memory_the_vessel_is_run_as_it_is():
    """fluid_memory=False: the paper's vessel as it is (no subsystem, no added mass of the
    dataset, its own damping only); the frequency domain is the same as with the memory, and the
    time domain is far from it (measured: +618 % in heave at 1.4 rad/s in head seas)."""
    ds = phsplit.rao(phsplit.Vessel.paper(), [1.4], 180.0, dofs="heave", fluid_memory=False, t_end=300.0)
    ds = ds.isel(frequency=0)
    assert ds.attrs["fluid_memory"] == 0 and float(ds["radiation_dissipated"]) == 0.0
    assert math.isclose(float(ds["heave_amplitude_frequency_domain"]), 0.02635, rel_tol=0.01)
    assert float(ds["heave_deviation"]) > 1.0 and "roll_amplitude" not in ds


@pytest.mark.parametrize("kwargs,words", [
    ({"vessel": "paper"}, r"^vessel must be a phsplit\.Vessel"),
    ({"frequencies": []}, r"^frequencies must be a non-empty list"),
    ({"frequencies": [0.5, -1.0]}, r"^frequencies must be a non-empty list"),
    ({"frequencies": ["fast"]}, r"^frequencies must be positive numbers"),
    ({"frequencies": [3.0]}, r"^frequencies: 3 rad/s is outside the dataset's 0\.2-2 rad/s"),
    ({"heading": 100.0}, r"^heading 100 deg is not a direction of the dataset"),
    ({"heading": "beam"}, r"^heading must be a number"),
    ({"dofs": ("heave", "rol")}, r"^dofs must be distinct names of surge, sway, heave, roll, pitch, yaw"),
    ({"dofs": ()}, r"^dofs must be distinct names"),
    ({"amplitude": 0.0}, r"^amplitude must be a positive number"),
    ({"h": -0.5}, r"^h must be a positive number"),
    ({"t_end": 100.0}, r"^t_end must be at least twice the fit window"),
    ({"method": "rk4x"}, r"^method must be one of"),
    ({"fluid_memory": "yes"}, r"^fluid_memory must be True, False or a FluidMemory"),
])
def test_bad_arguments_are_refused_in_one_line_naming_the_argument(kwargs, words):
    args = {"vessel": phsplit.Vessel.paper(), "frequencies": [0.56], "heading": 90.0} | kwargs
    with pytest.raises(phsplit.InvalidInputError, match=words) as e:
        phsplit.rao(args.pop("vessel"), args.pop("frequencies"), args.pop("heading"), **args)
    assert "\n" not in str(e.value)


def test_a_vessel_off_the_frequency_domains_assumptions_is_refused():
    d = phsplit.Vessel.paper().to_dict()
    d["vessel"]["center_of_gravity"] = [0.0, 0.0, 0.5]
    with pytest.raises(phsplit.InvalidInputError, match=r"^vessel: .* sets center_of_gravity$"):
        phsplit.rao(phsplit.Vessel.from_dict(d), [0.56], 90.0)


def test_motion_statistics_of_a_regular_wave_run_are_those_of_its_sinusoid():
    """Solution.motion_statistics over the steady state of a regular-wave run (the paper's vessel
    as it is, head seas of 0.1 m at 0.44 rad/s): for a sinusoid of amplitude a, sigma = a/sqrt(2),
    max = a and the significant double amplitude 4 sigma = 2 sqrt(2) a, a taken from the RAO fit
    of the same run."""
    paper = phsplit.Vessel.paper()
    got, s = seakeeping.time_rao(paper, seakeeping.waves_table(paper), 0.44, 180.0, amplitude=0.1, t_end=600.0)
    period = 2 * math.pi / 0.44
    st = s.motion_statistics(after=600.0 - 10 * period)
    for dof in ("heave", "pitch"):
        a = 0.1 * abs(got[dof])
        assert math.isclose(st[dof]["std"], a / math.sqrt(2), rel_tol=0.02), (dof, st[dof], a)
        assert math.isclose(st[dof]["significant"], 2 * math.sqrt(2) * a, rel_tol=0.02)
        assert math.isclose(st[dof]["max"], a + abs(st[dof]["mean"]), rel_tol=0.03)
        assert st[dof]["rms"] >= st[dof]["std"]
    assert st["roll"]["max"] < 1e-6   # head seas on a symmetric hull: no roll
    whole = s.motion_statistics()
    assert whole["heave"]["max"] >= st["heave"]["max"]
    with pytest.raises(phsplit.InvalidInputError, match=r"^after must leave at least two saved samples"):
        s.motion_statistics(after=601.0)
    with pytest.raises(phsplit.InvalidInputError, match=r"^after must be a time in seconds"):
        s.motion_statistics(after="end")
