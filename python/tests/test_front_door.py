"""The front door: what a user meets first on the command line and in scenario files.

``--vessel`` with a scenario keeps the scenario's tables; a shipped vessel's keys overridden one
by one; no stray files in an output folder; ``import phsplit`` gives every documented module;
directions in both conventions; progress and the whole command's time; readable figures;
output names from the scenario and the vessel; the ShipX supply vessel's preset name."""
from __future__ import annotations

import io
import math
import os
import re
import subprocess
from pathlib import Path
import sys
import time

import numpy as np
import pytest

import phsplit
from phsplit import cli, scenario, sea

# ----------------------------------------------------------------------------------------------
# --vessel with a scenario


def _components(path) -> list[str]:
    with phsplit.open_dataset(path) as ds:
        return [c.strip() for c in ds.attrs["components"].split(",")]


def test_vessel_option_keeps_the_scenarios_operation_and_environment(tmp_path):
    assert cli.main(["simulate", "pipelay", "--vessel", "paper", "--t-end", "4", "--out", str(tmp_path),
                     "--no-plot"]) == 0
    nc = tmp_path / "pipelay-paper-t4.nc"
    assert "pipe" in _components(nc)
    with phsplit.open_dataset(nc) as ds:
        tables = phsplit.Vessel.from_toml_str(ds.attrs["phsplit_vessel"]).to_dict()
        assert "setpoint_x" in ds and "thrust_utilisation" in ds
    assert {"pipe", "setpoint", "thrusters"} <= set(tables)
    assert tables["initial"]["position"] == [780.0, 20.0, 0.0]  # the scenario's, not the paper's
    sc = scenario.load("dp-weather", vessel="paper")
    assert {"current", "waves", "wind"} <= set(sc.vessel.components)


def test_vessel_option_runs_the_osv_in_the_scenarios_whole_sea(tmp_path):
    """The OSV in osv-weather (its own hull's dataset; the fluid memory left out here for speed):
    its own components and the scenario's waves, wind and current, each booked in its own
    account. The OSV in dp-weather, whose dataset is the paper box's, is refused: the dataset's
    hydrostatics are not the OSV's."""
    from phsplit import scenario as scenario_mod

    text = (Path(scenario_mod.SHIPPED_DIR) / "osv-weather.toml").read_text()
    text = text.replace("fluid_memory = true", "fluid_memory = false")
    text = text.replace('hydro = "osv_capytaine.nc"',
                        f'hydro = "{(Path(scenario_mod.SHIPPED_DIR) / "osv_capytaine.nc").as_posix()}"')
    sc = tmp_path / "osv-sea.toml"
    sc.write_text(text)
    p = subprocess.run([sys.executable, "-m", "phsplit", "simulate", str(sc), "--vessel", "osv", "--t-end", "4",
                        "--out", str(tmp_path / "out"), "--no-plot"], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    nc = tmp_path / "out" / "osv-weather-osv-t4.nc"
    assert {"crossflow_drag", "roll_damping", "current", "waves", "wind"} <= set(_components(nc))
    ledger = next(line for line in p.stdout.splitlines() if line.startswith("ledger, J:"))
    for a in ("crossflow_drag", "crossflow_current", "roll_damping", "current", "waves", "wave_drift", "wind"):
        assert f" {a} " in ledger, ledger
    p = subprocess.run([sys.executable, "-m", "phsplit", "simulate", "dp-weather", "--vessel", "osv", "--t-end", "4",
                        "--out", str(tmp_path / "out2"), "--no-plot"], capture_output=True, text=True, timeout=300)
    assert p.returncode == 2 and "vessel: the dataset's displacement" in p.stderr, p.stderr
    assert len(p.stderr.strip().splitlines()) == 1 and not (tmp_path / "out2").exists()


# ----------------------------------------------------------------------------------------------
# key-by-key overrides of a preset


def test_a_presets_vessel_table_is_overridden_key_by_key(tmp_path):
    f = tmp_path / "heavier.toml"
    f.write_text('[simulation]\nt_span = [0.0, 2.0]\n[vessel]\nfrom = "osv"\nmass = 6.0e6\n')
    sc = phsplit.load_scenario(str(f))
    osv = phsplit.Vessel.preset("osv").to_dict()["vessel"]
    got = sc.vessel.to_dict()["vessel"]
    assert got["mass"] == 6.0e6 != osv["mass"]
    assert {k: v for k, v in got.items() if k != "mass"} == {k: v for k, v in osv.items() if k != "mass"}
    assert sc.vessel.components == phsplit.Vessel.preset("osv").components


def test_a_string_and_a_table_named_vessel_get_a_hint_at_the_table_form(tmp_path):
    f = tmp_path / "both.toml"
    f.write_text('vessel = "osv"\n[vessel]\nmass = 6.0e6\n')
    with pytest.raises(phsplit.ScenarioParseError, match=r'\[vessel\] from = "osv"'):
        phsplit.load_scenario(str(f))
    f.write_text('[vessel]\nfrom = 3\n')
    with pytest.raises(phsplit.ScenarioParseError, match="vessel.from must be a shipped vessel's name"):
        phsplit.load_scenario(str(f))


# ----------------------------------------------------------------------------------------------
# no stray files


def test_an_output_folder_holds_only_the_outputs(tmp_path):
    for _ in range(2):  # and a second run over the same output takes its place
        assert cli.main(["simulate", "--t-end", "5", "--out", str(tmp_path)]) == 0
    assert sorted(os.listdir(tmp_path)) == ["fig2-t5.nc", "fig2-t5.png"]  # hidden files included


def test_the_temporary_file_is_the_lock(tmp_path):
    from phsplit.files import BusyError, PartialFile

    out = str(tmp_path / "run.nc")
    first = PartialFile(out)
    with pytest.raises(BusyError):
        PartialFile(out)
    with open(first.part, "w") as f:
        f.write("data")
    first.publish()
    assert sorted(os.listdir(tmp_path)) == ["run.nc"]
    second = PartialFile(out)  # free again once published
    second.discard()
    assert sorted(os.listdir(tmp_path)) == ["run.nc"] and open(out).read() == "data"


# ----------------------------------------------------------------------------------------------
# import phsplit


def test_import_phsplit_gives_sea_and_hydro():
    code = "import phsplit; print(phsplit.sea.SeaState(hs=2.0, tp=8.0).hs, callable(phsplit.hydro.from_capytaine))"
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert p.stdout.split() == ["2.0", "True"]


# ----------------------------------------------------------------------------------------------
# directions


def test_wave_and_wind_directions_in_both_conventions():
    base = {"hs": 2.0, "tp": 8.0, "seed": 3}
    towards = sea.sea_state({**base, "direction": 211.0}).realise()
    assert sea.sea_state({**base, "direction_towards": 211.0}).realise() == towards
    assert sea.sea_state({**base, "direction_from": 31.0}).realise() == towards
    w_towards, _ = sea.wind({"speed": 15.0, "direction": 200.0, "spectrum": "none"})
    w_from, _ = sea.wind({"speed": 15.0, "direction_from": 20.0, "spectrum": "none"})
    assert w_from == w_towards and w_from["direction"] == 200.0
    with pytest.raises(phsplit.InvalidInputError, match="direction, direction_from, not both"):
        sea.sea_state({**base, "direction": 1.0, "direction_from": 2.0})
    with pytest.raises(phsplit.InvalidInputError, match=r"environment.wind.direction_from must be a finite number"):
        sea.wind({"speed": 15.0, "direction_from": "north"})


def test_the_current_by_speed_and_direction():
    def current(table):
        return scenario.from_dict({"environment": {"current": table}}, "c.toml").vessel.to_dict()["current"]["velocity"]

    np.testing.assert_allclose(current({"speed": 0.5, "direction_towards": 90.0}), [0.0, 0.5, 0.0], atol=1e-15)
    np.testing.assert_allclose(current({"speed": 0.5, "direction_from": 90.0}), [0.0, -0.5, 0.0], atol=1e-15)
    np.testing.assert_allclose(current({"speed": 0.4, "direction": 0.0}), [0.4, 0.0, 0.0], atol=1e-15)
    assert current({"velocity": [0.1, 0.2, 0.0]}) == [0.1, 0.2, 0.0]  # as before
    line = scenario.describe_environment({"current": {"speed": 0.5, "direction_from": 90.0}})
    assert line == "current 0.50 m/s towards 270 deg"
    for bad, msg in [({"speed": 0.5}, "speed needs a direction"),
                     ({"direction_from": 10.0}, "needs the current's speed"),
                     ({"speed": -1.0, "direction": 0.0}, r"speed must be a number from 0 to 10 m/s .*, got -1.0"),
                     ({"speed": 1.0, "direction": 0.0, "velocity": [1.0, 0.0, 0.0]}, "not both")]:
        with pytest.raises(phsplit.InvalidInputError, match=msg):
            current(bad)


# ----------------------------------------------------------------------------------------------
# progress and time


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_progress_is_shown_for_any_run_that_lasts(monkeypatch):
    monkeypatch.setattr(sys, "stderr", _Terminal())
    bar = cli._progress_bar(100)  # a short run in steps; shown if it lasts
    try:
        assert not bar.disable
        assert 1.0 <= bar.delay <= 3.0
    finally:
        bar.close()


def test_progress_is_reported_while_a_chunk_runs():
    v = phsplit.Vessel.paper()
    s = phsplit.Settings(t_span=(0.0, 150_000.0), h=0.5, method="sp2", save_every=10_000, ledger=False)
    calls = []
    sols = list(phsplit.results.run_chunks(v, s, v.initial_state(), [300_000], progress=calls.append))
    assert sum(calls) == 300_000 == sols[0].steps
    assert len(calls) > 1  # during the call, not only at its end


def test_the_reported_time_is_the_whole_commands(tmp_path):
    # Each line as the command prints it (unbuffered), with the time it arrives: the reported
    # time runs from the process's start to the summary line, start-up and plotting included.
    t0 = time.perf_counter()
    p = subprocess.Popen([sys.executable, "-u", "-m", "phsplit", "simulate", "--t-end", "20", "--out",
                          str(tmp_path)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    arrived = {}
    for line in p.stdout:
        arrived.setdefault(line.split(":")[0], (time.perf_counter() - t0, line))
    _, err = p.communicate(timeout=300)
    assert p.returncode == 0, err
    at, line = arrived["completed"]
    m = re.search(r"completed: 40 steps in ([0-9.]+) s in all .*; integration and writing ([0-9.]+) s", line)
    assert m, line
    total, inner = float(m.group(1)), float(m.group(2))
    first = arrived["phsplit 0.1.0"][0] if "phsplit 0.1.0" in arrived else min(t for t, _ in arrived.values())
    assert inner < total <= at + 0.05
    assert total >= first  # the start-up before the first line counts
    assert total >= at - 0.3  # and so does everything up to the summary (the figure among it)


# ----------------------------------------------------------------------------------------------
# figures


def _boxes_overlap(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


def test_figures_hide_no_curve_and_keep_legends_off_the_data(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from phsplit.plotting import dp_figure

    assert cli.main(["simulate", "pipelay", "--t-end", "60", "--out", str(tmp_path), "--no-plot"]) == 0
    with phsplit.open_dataset(tmp_path / "pipelay-t60.nc") as ds:
        fig = dp_figure(ds)
    try:
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        legends = 0
        for ax in fig.axes:
            leg = ax.get_legend()
            if leg is not None:
                legends += 1
                # outside every axes' data area (its own, its twin's, the neighbours')
                for other in fig.axes:
                    assert not _boxes_overlap(leg.get_window_extent(renderer), other.get_window_extent(renderer)), (
                        [t.get_text() for t in leg.get_texts()])
            lines = [ln for a in fig.axes if a.bbox.bounds == ax.bbox.bounds for ln in a.get_lines()
                     if not ln.get_label().startswith("_")]
            looks = [(matplotlib.colors.to_hex(ln.get_color()), str(ln.get_linestyle()), str(ln.get_marker()),
                      str(ln.get_markevery())) for ln in lines]
            assert len(set(looks)) == len(looks), looks  # each curve of an axes looks different
        assert legends >= 7
        ax_rp = next(a for a in fig.axes if a.get_ylabel() == "roll, pitch [deg]")
        roll, pitch = (next(ln for ln in ax_rp.get_lines() if ln.get_label() == n) for n in ("roll", "pitch"))
        assert roll.get_linestyle() != pitch.get_linestyle() and roll.get_zorder() > pitch.get_zorder()
        ax_thr = next(a for a in fig.axes if a.get_ylabel() == "thrust [kN]")
        thrusters = [ln for ln in ax_thr.get_lines() if ln.get_label().startswith("thruster")]
        assert len(thrusters) == 4
        # thrusters 2 and 3 (the two azimuths) give the same thrust: both stay visible
        y2, y3 = thrusters[2].get_ydata(), thrusters[3].get_ydata()
        assert np.allclose(y2, y3, rtol=1e-6)
        assert thrusters[2].get_color() != thrusters[3].get_color()
        assert thrusters[2].get_marker() != thrusters[3].get_marker()
        assert thrusters[2].get_linewidth() > thrusters[3].get_linewidth()
        assert thrusters[2].get_markevery() != thrusters[3].get_markevery()
    finally:
        plt.close(fig)


# ----------------------------------------------------------------------------------------------
# names


def test_output_names_come_from_the_scenario_and_the_vessel(tmp_path):
    assert cli.main(["simulate", "--vessel", "osv", "--t-end", "4", "--out", str(tmp_path), "--no-plot"]) == 0
    assert cli.main(["simulate", "pipelay", "--vessel", "osv", "--t-end", "4", "--out", str(tmp_path),
                     "--no-plot"]) == 0
    assert sorted(os.listdir(tmp_path)) == ["osv-t4.nc", "pipelay-osv-t4.nc"]


def test_the_shipx_supply_vessel_is_named_after_its_source_and_the_old_name_still_works(capsys):
    assert "shipx-supply" in phsplit.presets() and "supply" not in phsplit.presets()
    new, old = phsplit.Vessel.preset("shipx-supply"), phsplit.Vessel.preset("supply")
    assert new.to_toml() == old.to_toml()
    assert "76.2 m" in phsplit.presets()["shipx-supply"][0]  # says it is not MSS's supply.m
    assert cli.main(["vessels"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^supply\s+the earlier name of shipx-supply", out, re.M), out
    assert scenario.vessel_named("supply").to_toml() == new.to_toml()
    assert math.isclose(new.to_dict()["vessel"]["mass"], 6362208.5)


def test_headings_and_euler_angles_in_degrees(tmp_path):
    f = tmp_path / "deg.toml"
    f.write_text("[initial]\neuler_deg = [0.0, 0.0, 30.0]\nposition = [0.0, 0.0, 0.0]\n"
                 "[control]\neuler_reference_deg = [0.0, 0.0, -90.0]\n")
    t = phsplit.load_scenario(str(f)).vessel.to_dict()
    np.testing.assert_allclose(t["initial"]["euler"], [0.0, 0.0, math.pi / 6], rtol=1e-15)
    np.testing.assert_allclose(t["control"]["euler_reference"], [0.0, 0.0, -math.pi / 2], rtol=1e-15)
    sc = phsplit.load_scenario("pipelay")
    f.write_text(open(sc.path).read().replace("headings = [0.54, 0.54]       # rad",
                                              "headings_deg = [30.94, 30.94]"))
    got = phsplit.load_scenario(str(f)).vessel.to_dict()["setpoint"]["headings"]
    np.testing.assert_allclose(got, [math.radians(30.94)] * 2, rtol=1e-15)
    f.write_text("[initial]\neuler = [0.0, 0.0, 0.5]\neuler_deg = [0.0, 0.0, 30.0]\n")
    with pytest.raises(phsplit.InvalidInputError, match=r"initial.euler \(rad\) or initial.euler_deg \(degrees\), not both"):
        phsplit.load_scenario(str(f))
    f.write_text('[initial]\neuler_deg = "north"\n')
    with pytest.raises(phsplit.InvalidInputError, match="initial.euler_deg must be a list of finite numbers"):
        phsplit.load_scenario(str(f))


def test_settings_that_cannot_act_are_reported():
    """A setting the run leaves without effect is said (SettingWarning), not dropped: a chosen
    controller start or a set point's start after the run's end, and a splitting method's flow
    choices (outer, linear_flow) with Runge-Kutta; the default start of a short run is not."""
    import warnings

    v = phsplit.Vessel.paper()
    with pytest.warns(phsplit.SettingWarning, match="control_start = 100 s is after the run's end"):
        phsplit.simulate(v, (0.0, 5.0), 0.5, "sp2", control_start=100.0)
    for kw, word in (({"outer": "conservative"}, "outer = 'conservative'"), ({"linear_flow": "exact"}, "linear_flow")):
        with pytest.warns(phsplit.SettingWarning, match=word):
            phsplit.simulate(v, (0.0, 2.0), 0.5, "rk4", **kw)
    with warnings.catch_warnings():
        warnings.simplefilter("error", phsplit.SettingWarning)
        phsplit.simulate(v, (0.0, 5.0), 0.5, "sp2")            # the default start, past a short run
        phsplit.simulate(v, (0.0, 2.0), 0.5, "rk4")            # the default flows
    d = phsplit.load_scenario("pipelay").vessel.to_dict()
    d["setpoint"]["start_time"] = 1e5
    with pytest.warns(phsplit.SettingWarning, match="setpoint.start_time = 100000 s is after the run's end"):
        phsplit.simulate(phsplit.Vessel.from_dict(d), (0.0, 2.0), 0.5, "sp2")
