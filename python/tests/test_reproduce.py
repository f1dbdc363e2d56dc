"""`phsplit reproduce --quick`: every file, the figures at their size, the data, the orders, and
clean failures."""
from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time

import matplotlib.image as mpimg
import pytest
import xarray as xr

import phsplit

FILES = {
    "fig2": ((660, 1320), {"position", "euler", "energy", "energy_supplied", "energy_dissipated"}),
    "fig3": ((880, 1100), {"relative_error", "fitted_order", "reference_accuracy"}),
    "fig4": ((880, 1210), {"sp2_vs_heun_split_energy_ratio", "sp4_vs_rk4_rk_control",
                           "sp4_vs_rk4_exact_energy_ratio"}),
    "stability": ((605, 990), {"energy_end", "diverged"}),
}


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduction")
    r = subprocess.run([sys.executable, "-m", "phsplit", "reproduce", "--quick", "--out", str(out)],
                       capture_output=True, text=True, timeout=600)
    return out, r


def test_every_file_is_written(quick_run):
    out, r = quick_run
    assert r.returncode == 0, r.stdout + r.stderr
    names = set(os.listdir(out))
    expected = {f"{n}.{e}" for n in FILES for e in ("png", "pdf", "nc")} | {"report.md", "report.html"}
    assert names == expected, names ^ expected  # nothing missing, no staging leftovers
    assert "claims hold" in r.stdout


def test_figures_have_the_expected_size(quick_run):
    out, _ = quick_run
    for name, (shape, _) in FILES.items():
        img = mpimg.imread(out / f"{name}.png")
        assert img.shape[:2] == shape, (name, img.shape)
        assert img[..., :3].std() > 0.05, f"{name}.png looks blank"
        assert (out / f"{name}.pdf").read_bytes()[:5] == b"%PDF-"


def test_netcdf_files_hold_the_data(quick_run):
    out, _ = quick_run
    for name, (_, variables) in FILES.items():
        with phsplit.open_dataset(out / f"{name}.nc") as ds:
            assert variables <= set(ds.data_vars), (name, set(ds.data_vars))


def test_netcdf_files_are_cf_compliant(quick_run):
    from test_results import cf_problems

    out, _ = quick_run
    for name in FILES:
        assert cf_problems(out / f"{name}.nc") == [], name


def test_report_orders_and_claims(quick_run):
    out, _ = quick_run
    md = (out / "report.md").read_text()
    for meth, order in (("SP2", 2), ("SP4", 4), ("SP6", 6)):
        row = re.search(rf"^\| {meth} \| ([\d.]+) \| ([\d.]+) \| ([\d.]+) \| ([\d.]+) \|$", md, re.M)
        assert row, meth
        slopes = [float(v) for v in row.groups()]
        assert all(abs(v - order) <= 0.2 for v in slopes), (meth, slopes)
    assert "**no**" not in md
    html = (out / "report.html").read_text()
    assert html.count("data:image/png;base64,") == 4 and "<table>" in html


def test_unwritable_output_folder(tmp_path):
    blocker = tmp_path / "a_file"
    blocker.write_text("x")
    r = subprocess.run([sys.executable, "-m", "phsplit", "reproduce", "--quick", "--out", str(blocker / "sub")],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "cannot create output folder" in r.stderr and "Traceback" not in r.stderr


def test_unknown_option():
    r = subprocess.run([sys.executable, "-m", "phsplit", "reproduce", "--fast"], capture_output=True, text=True)
    assert r.returncode == 2 and "unrecognized arguments: --fast" in r.stderr


def test_interrupted_run_leaves_nothing_behind(tmp_path):
    p = subprocess.Popen([sys.executable, "-m", "phsplit", "reproduce", "--quick", "--out", str(tmp_path)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    # Wait until the run is under way (its staging folder exists), then stop it.
    deadline = time.monotonic() + 120
    while not any(n.startswith(".phsplit-reproduce-") for n in os.listdir(tmp_path)):
        assert p.poll() is None, p.communicate()
        assert time.monotonic() < deadline, "the run never started"
        time.sleep(0.05)
    time.sleep(1.0)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130, err
    assert "interrupted" in err
    assert os.listdir(tmp_path) == []


def test_a_run_interrupted_inside_the_core_stops_the_study():
    """Ctrl-C while the core integrates returns a cut run with status "interrupted"; the study
    must stop there (KeyboardInterrupt, which the CLI turns into exit 130 and an empty output
    folder), not go on with the cut run (a cut reference once failed to broadcast in fig. 4)."""
    from phsplit import reproduce as rp

    def stop(done, total):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        rp.simulate_as_printed(phsplit.Vessel.paper(), (0.0, 2000.0), 0.002, "sp2", control_start=0.0, progress=stop)
    # The library's own simulate returns the cut run (documented), so the check is the study's.
    sol = phsplit.simulate(phsplit.Vessel.paper(), (0.0, 2000.0), 0.002, "sp2", control_start=0.0, progress=stop)
    assert sol.status == "interrupted" and sol.t[-1] < 2000.0
