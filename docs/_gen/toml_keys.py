"""Writes the TOML reference (docs/reference/toml.md runs it during the build).

Which keys exist is asked of the code itself: the core's settings table
(``phsplit._core.settings_keys``, ``default_settings``) and, for every other table, the list of
allowed keys that the parser prints when it meets an unknown one. Units, defaults and meanings
are written below from the modules that read each table (their module docs, named in SOURCE).
The build fails when the two disagree: a key the code accepts and this file does not describe,
a key described here that the code no longer accepts, a key documented as required that may be
left out (or the reverse), or a literal default that is not what the parser fills in. Units and
meanings are not checked: they drift only with the modules they were written from.
"""
from __future__ import annotations

import copy
import re

import phsplit
from phsplit import _core, batch, scenario, sea

REQ = "required"
OPT = "optional"

# (unit, default, meaning). Units are SI; "-" means dimensionless or not a number.
KEYS: dict[str, dict[str, tuple[str, str, str]]] = {
    "vessel": {
        "mass": ("kg", REQ, "rigid-body mass `mv` (paper App. D), in (0, 1e9]"),
        "inertia": ("kg m²", REQ, "principal moments of inertia `T1, T2, T3` about the centre of gravity, each in (0, 1e14]"),
        "center_of_gravity": ("m", "[0, 0, 0]", "centre of gravity from the body origin, body frame, z up (§5.14)"),
        "added_mass": ("kg, kg m, kg m²", "none", "6×6 symmetric added mass `M_A`; `M = M_RB + M_A` must be positive definite (§5.14)"),
        "damping_translational": ("kg/s", REQ + " (or `damping_matrix`)", "diagonal linear damping `Dt`, ≥ 0 (§2.4)"),
        "damping_rotational": ("kg m²/s", REQ + " (or `damping_matrix`)", "diagonal linear damping `Dr`, ≥ 0 (§2.4)"),
        "damping_matrix": ("SI per entry", "none", "full 6×6 linear damping, symmetric positive semidefinite, instead of the diagonals (§5.13)"),
        "gm_transverse": ("m", REQ, "transverse metacentric height, in (0, 2000] (§2.3)"),
        "gm_longitudinal": ("m", REQ, "longitudinal metacentric height, in (0, 2000] (§2.3)"),
        "gravity": ("m/s²", REQ, "acceleration of gravity, in [9.7, 9.9]"),
        "water_density": ("kg/m³", REQ, "water density, in [950, 1250]"),
        "waterplane_area": ("m²", REQ, "waterplane area `A_wp`, > 0 (heave stiffness `ρ g A_wp`)"),
        "flotation_center_x": ("m", "0", "centre of flotation, body x; couples heave and pitch (§5.15)"),
        "flotation_center_y": ("m", "0", "centre of flotation, body y; couples heave and roll (§5.15)"),
    },
    "initial": {
        "euler": ("rad", REQ, "ZYX Euler angles (roll, pitch, yaw), eq. (21)"),
        "position": ("m", REQ, "position of the body origin, spatial frame, z up, each within ±1e7"),
        "velocity": ("m/s", "[0, 0, 0]", "linear velocity, body frame"),
        "angular_velocity": ("rad/s", "[0, 0, 0]", "angular velocity, body frame"),
    },
    "control": {
        "kp_translational": ("N/m", REQ, "proportional gains on the position error (diagonal, ≥ 0; paper §3.1)"),
        "kd_translational": ("N s/m", REQ, "derivative gains, booked as `control_damping`"),
        "ki_translational": ("N/(m s)", REQ, "integral gains"),
        "kp_rotational": ("N m/rad", REQ, "proportional gains on the Euler-angle error"),
        "kd_rotational": ("N m s/rad", REQ, "derivative gains"),
        "ki_rotational": ("N m/(rad s)", REQ, "integral gains"),
        "euler_reference": ("rad", REQ, "set attitude (roll, pitch, yaw), each within ±2π"),
        "position_reference": ("m", REQ, "set position, spatial frame, each within ±1e7"),
        "feedback": ("-", '"true_state"', '`"true_state"` (the paper\'s) or `"observer"`: the controller acts on the estimates of `[observer]` (§5.20)'),
        "anti_windup": ("-", '"none"', '`"none"` or `"back_calculation"` (Åström–Hägglund): the integral states are pulled towards what `[thrusters]` deliver while they saturate; needs `[thrusters]` and an integral gain'),
        "tracking_time": ("s", "√(kd/ki) per axis", "back-calculation's tracking time `T_t` for every axis, in (0, 86400]; needs `anti_windup = \"back_calculation\"`"),
    },
    "observer": {
        "wave_frequency": ("rad/s", REQ, "`ω₀` of the wave model, in (0, 10]: the sea's peak frequency (§5.20)"),
        "damping": ("kg/s, kg/s, kg m²/s", REQ, "the observer's model damping in surge, sway, yaw, in [0, 1e13]"),
        "wave_damping": ("-", "0.1", "`λ` of the wave model, > 0"),
        "notch_damping": ("-", "1", "`ζₙ` of the notch, > `λ`"),
        "cutoff_frequency": ("rad/s", "1.2255 ω₀", "`ω_c` of the wave filter, > `ω₀`"),
        "bias_time_constant": ("s", "1000", "`T` of the bias model, > 0"),
        "bias_bandwidth": ("rad/s", "ω₀/5", "`ω_b` at which `K₃`, `K₄` place the low-frequency error dynamics critically damped"),
        "velocity_gain": ("N/m, N/m, N m/rad", "placed at `ω_b`", "`K₄`, in (0, 1e16]; with `bias_gain`, `1/T < K₃/K₄ < ω₀`"),
        "bias_gain": ("N/(m s), N/(m s), N m/(rad s)", "placed at `ω_b`", "`K₃`, in (0, 1e16]"),
        "initial_estimate": ("m, m, rad", "the measured", "initial `(x̂, ŷ, ψ̂)`: within 10 km of the set point, the heading within ±2π"),
        "initial_bias": ("N, N, N m", "[0, 0, 0]", "initial bias estimate, spatial frame, each within ±1e10"),
    },
    "sensors": {
        "gnss_rate": ("Hz", REQ, "the GNSS position's sample rate, in (0, 1000]; samples held between (§5.20, *Sensors*)"),
        "gyro_rate": ("Hz", REQ, "the gyro heading's sample rate, in (0, 1000]"),
        "gnss_noise": ("m", "0", "standard deviation of the white noise on each horizontal axis, in [0, 100]"),
        "gnss_bias": ("m", "[0, 0]", "constant bias of the position, spatial x and y, each within ±1000"),
        "gyro_noise": ("rad", "0", "standard deviation of the white noise on the heading, in [0, 0.5]"),
        "gyro_bias": ("rad", "0", "constant bias of the heading, within ±0.5"),
        "gnss_dropout": ("s", "none", "rows `[start, end]` in time order: the receiver delivers nothing in between"),
        "gyro_dropout": ("s", "none", "rows `[start, end]`: the gyro delivers nothing in between"),
        "seed": ("-", "0", "whole number ≥ 0: the noise of sample k is drawn from (seed, sensor, k)"),
        "gnss_antenna": ("m", "[0, 0, 0]", "the GNSS antenna, body frame from the body origin, each within ±250: its fix is referred to the origin with the MRU's roll and pitch and the gyro's heading"),
        "mru_noise": ("rad", "0", "standard deviation of the MRU's roll and pitch noise, in [0, 0.1] (read at each GNSS sample; needs gnss_antenna)"),
        "mru_bias": ("rad", "[0, 0]", "constant bias of the MRU's roll and pitch, each within ±0.1 (needs gnss_antenna)"),
    },
    "external": {
        "force": ("N", "[0, 0, 0]", "constant force (§5.4)"),
        "moment": ("N m", "[0, 0, 0]", "constant moment"),
        "point": ("m", "[0, 0, 0]", "point of application, body frame, each component within ±1000 m"),
        "frame": ("-", '"body"', '`"body"` or `"spatial"`: the frame of `force` and `moment`'),
    },
    "current": {
        "velocity": ("m/s", "[0, 0, 0]", "uniform current, spatial frame, towards; each component within ±10 m/s (§5.5)"),
        "times": ("s", "none", "instead of `velocity`: increasing times of a current table"),
        "velocities": ("m/s", "none", "one row of 3 numbers per time; linear in between, constant outside"),
        "speed": ("m/s", "none", "instead of `velocity`: the current's speed, 0 to 10, with one direction key"),
        "direction": ("degrees", "none", "with `speed`: where the water flows towards, spatial, from x towards y"),
        "direction_towards": ("degrees", "none", "the same as `direction`"),
        "direction_from": ("degrees", "none", "with `speed`, instead: where the water comes from"),
    },
    "damping_quadratic": {
        "coefficients": ("kg/m (surge, sway, heave), kg m² (roll, pitch, yaw)", REQ,
                         "six magnitudes `≥ 0` of Fossen's `X_|u|u … N_|r|r` (§5.11)"),
    },
    "roll_damping": {
        "linear": ("N m s", "none", "`B₁` of the roll moment `−B₁ p − B₂ |p| p`, `≥ 0` (§5.19); or, instead:"),
        "critical_fraction": ("-", "none", "`ζ` in [0, 1): `B₁ = 2ζ√(M₄₄ C₄₄)` of the vessel's mass matrix and roll stiffness"),
        "quadratic": ("N m s²", "0", "`B₂ ≥ 0`; at least one of `B₁`, `B₂` is > 0"),
    },
    "crossflow_drag": {
        "draft": ("m", REQ, "draught `T`, in (0, 40] (§5.12; [physical ranges](#physical-ranges))"),
        "drag_coefficient": ("-", REQ, "2-D drag coefficient `C_d`, in (0, 5]"),
        "x_aft": ("m", REQ, "body x of the aft end of the hull, within ±1000 m"),
        "x_fore": ("m", REQ, "body x of the fore end, `x_aft < x_fore`"),
    },
    "pipe": {
        "model": ("-", '"catenary"', "`catenary` (the natural catenary, quasi-static, §5.6) or `lumped_mass` (the dynamic pipe, §5.18, keys below)"),
        "submerged_weight": ("N/m", REQ, "pipe weight in water `w`, > 0 (§5.6)"),
        "water_depth": ("m", REQ, "seabed below the still water line, in (0, 11000]"),
        "hang_off": ("m", REQ, "where the pipe leaves the vessel, body frame, above the seabed"),
        "horizontal_tension": ("N", "one of four", "horizontal tension `H`, held by the tensioner"),
        "top_tension": ("N", "one of four", "top tension `T`, instead"),
        "departure_angle": ("degrees", "one of four", "angle from the horizontal at the hang-off point, in [5, 90)"),
        "touchdown": ("m", "one of four", "`[x, y]` of the touchdown point, spatial"),
        "lay_direction": ("degrees", "required with a tension or an angle", "lay direction, spatial, from x towards y, within ±360"),
        "lay_speed": ("m/s", "0", "with `touchdown`: speed of the touchdown point along `lay_direction`"),
    },
    "pipe.lumped_mass": {
        "model": ("-", REQ, '`"lumped_mass"`: the dynamic pipe (§5.18)'),
        "length": ("m", REQ, "unstretched length, longer than the hang-off point's height above the seabed"),
        "segments": ("-", REQ, "number of segments `N`, an integer from 2 to 1000"),
        "axial_stiffness": ("N", REQ, "axial stiffness `EA`, > 0"),
        "mass": ("kg/m", REQ, "mass per length in air, more than the displaced water"),
        "diameter": ("m", REQ, "hydrodynamic outer diameter (over any coating), in (0, 5]"),
        "water_depth": ("m", REQ, "seabed below the still water line, in (0, 11000]"),
        "hang_off": ("m", REQ, "where the pipe leaves the vessel, body frame, above the seabed"),
        "anchor": ("m", REQ, "`[x, y]` of the pipe's far end on the seabed, spatial, within `length` of the hang-off point where the run starts"),
        "drag_normal": ("-", "1.2", "normal drag coefficient `C_dn` (MoorDyn's default), ≥ 0"),
        "drag_tangential": ("-", "0.008", "tangential drag coefficient `C_dt` on `π d l`, ≥ 0"),
        "added_mass": ("-", "1.0", "added-mass coefficient `C_a`, isotropic, ≥ 0"),
        "seabed_stiffness": ("Pa/m", "3000000.0", "seabed stiffness `k_b` per contact area `d l` (MoorDyn's `kbot`)"),
        "seabed_damping": ("Pa s/m", "300000.0", "seabed damping `c_b` per contact area (MoorDyn's `cbot`)"),
        "axial": ("-", '"tension_only"', "`tension_only` (slack segments carry nothing) or `tension_and_compression`"),
        "axial_damping": ("N s", "0.0", "segments' internal damping `BA` (MoorDyn's), ≥ 0"),
        "bending_stiffness": ("N m²", "0.0", "bending stiffness `EI`: a rotational spring `(EI/l)(1 − cos θ)` at each free node, ≥ 0"),
    },
    "spring": {
        "fairlead": ("m", REQ, "the fairlead, body frame, from the body origin, each component within ±1000 m (§5.16)"),
        "anchor": ("m", REQ, "the anchor, spatial frame, z up"),
        "stiffness": ("N/m", REQ, "the spring's stiffness `k`, > 0"),
    },
    "port_hamiltonian": {
        "name": ("-", '"port_hamiltonian"', "names its account and outputs: letters, digits, `_`, starting with a letter (§5.17)"),
        "states": ("-", REQ, "the names of its `n` states, distinct, 1 to 64"),
        "units": ("-", '"1" each', "a CF unit per state"),
        "J": ("-", REQ, "`n×n`, skew-symmetric: the conservative interconnection"),
        "R": ("-", REQ, "`n×n`, symmetric positive semidefinite: the dissipation"),
        "Q": ("-", REQ, "`n×n`, symmetric positive definite: the storage `½ xᵀQx`"),
        "G": ("-", REQ, "`n×k`: the input map"),
        "P": ("-", "zero", "`n×k`: the input's dissipative part, `[[R, P], [Pᵀ, S]] ⪰ 0`"),
        "S": ("-", "zero", "`k×k`, symmetric: the feedthrough's dissipative part"),
        "N": ("-", "zero", "`k×k`, skew-symmetric: the feedthrough's conservative part"),
        "input": ("-", REQ, "the `k` degrees of freedom of the body velocity it takes: `surge`, `sway`, `heave`, `roll`, `pitch`, `yaw`"),
        "point": ("m", "[0, 0, 0]", "body frame: the translational inputs are this point's velocity, and the force acts there"),
        "initial": ("the states' units", "zeros", "the states where a run starts, storing at most 1e12 J (½ xᵀQx)"),
    },
    "setpoint": {
        "natural_frequency": ("rad/s", REQ, "ω of Fossen's third-order reference model, > 0 (§5.7)"),
        "relative_damping": ("-", "1", "ζ, > 0 (1: critically damped)"),
        "positions": ("m", REQ, "rows of 3 numbers, spatial: the set points or waypoints"),
        "headings": ("rad", "the fixed heading", "one yaw per row, within ±2π (radians, not degrees)"),
        "times": ("s", "one of `times`, `speed`", "increasing times of the rows, within ±1e9 s"),
        "speed": ("m/s", "one of `times`, `speed`", "rows are waypoints passed at this speed, > 0"),
        "start_time": ("s", "0", "with `speed`: when the set point starts moving, within ±1e9 s"),
        "interpolation": ("-", '"linear"', '`"linear"` or `"step"` between rows'),
    },
    "thrusters": {
        "hull_length": ("m", REQ, "the hull's box `|x| ≤ L/2`, inside which every thruster sits, in (0, 500] (§5.8)"),
        "hull_beam": ("m", REQ, "the box's `|y| ≤ B/2`, `|z| ≤ B/2`, in (0, 150]"),
        "unit": ("-", REQ, "the list of thrusters, `[[thrusters.unit]]` tables (below); rank 3 in surge, sway and yaw"),
    },
    "thrusters.unit": {
        "kind": ("-", REQ, '`"tunnel"`, `"azimuth"` or `"fixed"`'),
        "position": ("m", REQ, "body frame, from the body origin"),
        "max_thrust": ("N", REQ, "> 0"),
        "min_thrust": ("N", "−max_thrust (tunnel); required (fixed)", "tunnel and fixed: the reverse thrust, < 0"),
        "angle": ("degrees", "90 (tunnel), 0 (fixed)", "tunnel and fixed: the axis in the body x–y plane, from x towards y, within ±360"),
        "weight": ("-", "1", "cost of its thrust in the allocation, > 0"),
        "thrust_rate": ("N/s", "none", "fastest change of thrust, > 0"),
        "turn_rate": ("degrees/s", "none", "azimuth: fastest turn, > 0"),
        "lost_at": ("s", "none", "the time the thruster is lost: from then it delivers nothing and the allocation redistributes the demand (§5.8); within ±1e9 s, at or before the start: lost from the start"),
        "stuck_at": ("s", "none", "the time the thruster fails as set: from then it keeps the thrust and angle it delivered at the end of the step before, and the allocation redistributes the rest of the demand (§5.8); within ±1e9 s; not with lost_at"),
    },
    "waves": {
        "frequencies": ("rad/s", REQ, "ω_k of the sea state's components, > 0 (realised by `phsplit.sea`; §5.9)"),
        "amplitudes": ("m", REQ, "a_k, ≥ 0"),
        "phases": ("rad", REQ, "φ_k"),
        "directions": ("degrees", REQ, "β_k, the direction each component travels towards"),
        "rao_frequencies": ("rad/s", REQ, "increasing, covering every component's frequency"),
        "rao_directions": ("degrees", REQ, "relative to the hull, increasing, spanning less than 360"),
        "force_rao_real": ("N/m, N m/m", REQ, "`[direction][frequency][6]`, real part of the excitation per metre of amplitude"),
        "force_rao_imag": ("N/m, N m/m", REQ, "imaginary part, the same shape"),
        "drift_coefficients": ("N/m², N m/m²", "none", "`[direction][frequency][3]`, mean drift in surge, sway, yaw (Newman)"),
        "phase_at": ("-", '"reference"', '`"reference"` (a fixed point) or `"vessel"` (the body origin)'),
    },
    "wind": {
        "speed": ("m/s", REQ, "mean wind speed, ≥ 0, ≤ 80 (§5.10)"),
        "direction": ("degrees", REQ, "the direction the wind blows towards, spatial"),
        "gust_frequencies": ("rad/s", "together: all three or none", "gust components (realised by `phsplit.sea.Wind`), > 0"),
        "gust_amplitudes": ("m/s", "together: all three or none", "≥ 0"),
        "gust_phases": ("rad", "together: all three or none", "one per gust component"),
        "frontal_area": ("m²", REQ, "frontal projected area `A_F`, > 0"),
        "lateral_area": ("m²", REQ, "lateral projected area `A_L`, > 0"),
        "length": ("m", REQ, "length `L` for the yaw moment, > 0"),
        "air_density": ("kg/m³", REQ, "> 0"),
        "angles": ("degrees", REQ, "relative wind angles of the coefficient table, increasing, spanning less than 360"),
        "cx": ("-", REQ, "surge coefficient per angle"),
        "cy": ("-", REQ, "sway coefficient per angle"),
        "cn": ("-", REQ, "yaw coefficient per angle"),
    },
    "simulation": {},  # from the core's settings table, below
    "environment.waves": {
        "hs": ("m", REQ, "significant wave height"),
        "tp": ("s", REQ, "peak period"),
        "gamma": ("-", "3.3", "JONSWAP peak enhancement"),
        "spectrum": ("-", '"jonswap"', '`"jonswap"` or `"pierson-moskowitz"`, through wavespectra'),
        "direction": ("degrees", "0", "the direction the waves travel towards"),
        "direction_towards": ("degrees", "none", "the same as `direction` (give one of the three)"),
        "direction_from": ("degrees", "none", "the direction the waves come from, instead"),
        "spreading": ("-", "none (long-crested)", "exponent `s` of the cos-2s spreading function"),
        "direction_sampling": ("-", '"quasi_random"', 'with `spreading`: `"quasi_random"` (each component\'s direction at a '
                               'golden-ratio quantile of the spreading) or `"random"` (independent draws)'),
        "seed": ("-", "0", "the same seed, the same sea"),
        "components": ("-", "200", "number of regular components, 1 to 10,000"),
        "omega_range": ("rad/s", "[0.5, 3] ω_p", "two increasing frequencies > 0; by default, with `hydro`, within the dataset's frequencies"),
        "hydro": ("-", "none", "a Capytaine dataset (path relative to the scenario) for the transfer functions"),
        "symmetric": ("-", "false", "mirror 0–180 degrees for a port–starboard symmetric hull; without it, waves "
                      "from a direction the dataset does not cover are refused"),
        "hydro_checks": ("-", '"refuse"', '`"refuse"` a dataset that fails a physics check, or `"warn"` and use it'),
        "fluid_memory": ("-", "false", "add the dataset's Cummins fluid memory: the subsystem `radiation` and "
                         "`A∞` as `vessel.added_mass` (needs `hydro`; Example: Cummins' fluid memory)"),
    },
    "environment.wind": {
        "speed": ("m/s", REQ, "mean speed at 10 m"),
        "direction": ("degrees", "0", "towards"),
        "direction_towards": ("degrees", "none", "the same as `direction` (give one of the three)"),
        "direction_from": ("degrees", "none", "where the wind comes from, instead"),
        "spectrum": ("-", '"npd"', '`"npd"`, `"harris"` or `"none"`: the gust spectrum'),
        "seed": ("-", "0", "the gusts' seed"),
        "components": ("-", "100", "number of gust components"),
        "omega_range": ("rad/s", "[0.001, 0.5]", "gust frequency range (the slowly-varying band)"),
        "height": ("m", "10", "reference height of `speed`"),
        "drag": ("-", "0.002", "surface drag coefficient of the Harris spectrum"),
        "ship_type": ("-", "none", "Blendermann's (1994) coefficients for one of `phsplit.sea.blendermann`'s ship types"),
        "centroid_x": ("m", "0", "with `ship_type`: body x of the lateral area's centroid"),
        "frontal_area": ("m²", "the vessel file's", "as in `[wind]`"),
        "lateral_area": ("m²", "the vessel file's", "as in `[wind]`"),
        "length": ("m", "the vessel file's", "as in `[wind]`"),
        "air_density": ("kg/m³", "the vessel file's", "as in `[wind]`"),
        "angles": ("degrees", "from `ship_type`", "as in `[wind]`"),
        "cx": ("-", "from `ship_type`", "as in `[wind]`"),
        "cy": ("-", "from `ship_type`", "as in `[wind]`"),
        "cn": ("-", "from `ship_type`", "as in `[wind]`"),
    },
    "sweep": {
        "mode": ("-", '"grid"', '`"grid"` (the product of the lists) or `"random"`'),
        "samples": ("-", "required with random", "number of random cases"),
        "seed": ("-", "0", "seed of the random cases"),
        "parameters": ("-", REQ, "a table: parameter path → list (grid, or choice) or `{low, high}` (uniform)"),
    },
}

SOURCE = {
    "vessel": "`model/vessel/body.rs`, `forces/damping.rs`, `forces/restoring.rs`",
    "initial": "`model/vessel/mod.rs`",
    "control": "`forces/pid.rs`",
    "external": "`forces/external.rs`",
    "current": "`forces/current.rs`",
    "damping_quadratic": "`forces/damping_quadratic.rs`",
    "roll_damping": "`forces/roll_damping.rs`",
    "observer": "`forces/observer.rs`",
    "sensors": "`forces/sensors.rs`",
    "crossflow_drag": "`forces/crossflow.rs`",
    "pipe": "`forces/pipe.rs`",
    "pipe.lumped_mass": "`forces/pipe/lumped.rs`",
    "spring": "`forces/spring.rs`",
    "port_hamiltonian": "`forces/port_hamiltonian.rs`",
    "setpoint": "`forces/pid.rs`",
    "thrusters": "`forces/thrusters.rs`",
    "thrusters.unit": "`forces/thrusters.rs`",
    "waves": "`forces/waves.rs`",
    "wind": "`forces/wind.rs`",
    "simulation": "`crates/phsplit-core/src/settings.rs`",
    "environment.waves": "`python/src/phsplit/sea.py` (`sea_state`)",
    "environment.wind": "`python/src/phsplit/sea.py` (`wind`)",
    "sweep": "`python/src/phsplit/batch.py` (`load_sweep`)",
}


def _allowed(message: str) -> set[str]:
    m = re.search(r"\(allowed: ([^)]*)\)", str(message))
    if not m:
        raise RuntimeError(f"no list of allowed keys in {message!r}")
    return {k.strip() for k in m.group(1).split(",")}


def _probe(call) -> set[str]:
    try:
        call()
    except (_core.InvalidInputError, _core.ScenarioParseError) as e:
        return _allowed(e)
    raise RuntimeError("an unknown key was accepted")


def accepted() -> dict[str, set[str]]:
    """The keys each table accepts, as the code itself lists them."""
    paper = phsplit.Vessel.paper().to_dict()
    examples = [paper,
                scenario.load("pipelay").vessel.to_dict(),
                scenario.load("dp-weather").vessel.to_dict(),
                phsplit.Vessel.preset("osv").to_dict(),
                {**paper, "external": {"force": [1.0, 0.0, 0.0]},
                 "damping_quadratic": {"coefficients": [0.0] * 6},
                 "roll_damping": {"critical_fraction": 0.05}},
                _examples()["observer"], _examples()["sensors"],
                _examples()["spring"], _examples()["port_hamiltonian"]]
    out: dict[str, set[str]] = {}
    for table in _core.vessel_tables():
        src = next(d for d in examples if table in d)
        d = copy.deepcopy(src)
        d[table]["zz_unknown"] = 0
        out[table] = _probe(lambda: phsplit.Vessel.from_dict(d))
    d = copy.deepcopy(_lumped())
    d["pipe"]["zz_unknown"] = 0
    out["pipe.lumped_mass"] = _probe(lambda: phsplit.Vessel.from_dict(d))
    units = set()
    pipelay = scenario.load("pipelay").vessel.to_dict()
    for kind in ("tunnel", "azimuth", "fixed"):
        d = copy.deepcopy(pipelay)
        u = d["thrusters"]["unit"][0]
        u.update(kind=kind, zz_unknown=0)
        if kind == "fixed":
            u["min_thrust"] = -1.0e5
        units |= _probe(lambda: phsplit.Vessel.from_dict(d))
    out["thrusters.unit"] = units
    out["simulation"] = {k for k, _ in _core.settings_keys()}
    out["environment.waves"] = _probe(lambda: sea.sea_state({"hs": 1.0, "tp": 9.0, "zz_unknown": 0}))
    out["environment.wind"] = _probe(lambda: sea.wind({"speed": 1.0, "zz_unknown": 0}))
    out["sweep"] = set(batch.SWEEP_KEYS)
    return out


def _examples() -> dict[str, dict]:
    """A valid vessel file (as tables) that has each vessel table."""
    paper = phsplit.Vessel.paper().to_dict()
    pipelay = scenario.load("pipelay").vessel.to_dict()
    weather = scenario.load("dp-weather").vessel.to_dict()
    return {"vessel": paper, "initial": paper, "control": paper, "external": {**paper, "external": {"force": [1.0, 0.0, 0.0]}},
            "current": weather, "pipe": pipelay, "setpoint": pipelay, "thrusters": pipelay, "waves": weather,
            "wind": weather, "crossflow_drag": phsplit.Vessel.preset("osv").to_dict(),
            "damping_quadratic": {**paper, "damping_quadratic": {"coefficients": [1.0] * 6}},
            "roll_damping": {**paper, "roll_damping": {"critical_fraction": 0.05, "quadratic": 1.0e9}},
            "observer": {**paper, "control": {**paper["control"], "feedback": "observer"},
                         "observer": {"wave_frequency": 0.7, "damping": [3.5e4, 1.2e5, 3.2e8]}},
            "sensors": {**paper, "control": {**paper["control"], "feedback": "observer"},
                        "observer": {"wave_frequency": 0.7, "damping": [3.5e4, 1.2e5, 3.2e8]},
                        "sensors": {"gnss_rate": 1.0, "gyro_rate": 10.0}},
            "spring": {**paper, "spring": {"fairlead": [30.0, 0.0, 0.0], "anchor": [700.0, 0.0, -5.0], "stiffness": 1.0e4}},
            "port_hamiltonian": {**paper, "port_hamiltonian": {
                "name": "port_hamiltonian", "states": ["q", "p"], "units": ["1", "1"], "J": [[0.0, 1.0], [-1.0, 0.0]],
                "R": [[0.0, 0.0], [0.0, 1.0]], "Q": [[1.0, 0.0], [0.0, 1.0]], "G": [[1.0], [0.0]], "P": [[0.0], [0.0]],
                "S": [[0.0]], "N": [[0.0]], "input": ["roll"], "point": [0.0, 0.0, 0.0], "initial": [0.0, 0.0]}}}


def _lumped() -> dict:
    """A valid vessel file with the dynamic pipe (the pipelay-dynamic scenario's)."""
    return scenario.load("pipelay-dynamic").vessel.to_dict()


def _literal(text: str):
    """The value a documented default stands for, when it is one literal (else None)."""
    import tomllib

    try:
        return tomllib.loads(f"x = {text}")["x"]
    except tomllib.TOMLDecodeError:
        return None


def check_defaults() -> list[str]:
    """Each documented default of a vessel table against the parser: a key documented as
    required must be refused when absent, and a literal default must be what the parser fills
    in when the key is left out (where it reports the value back)."""
    problems = []
    cases = [(table, table, d) for table, d in _examples().items()] + [("pipe", "pipe.lumped_mass", _lumped())]
    for table, doc, d in cases:
        for key in list(d[table]):
            unit, default, _ = KEYS[doc][key]
            e = copy.deepcopy(d)
            del e[table][key]
            try:
                filled = phsplit.Vessel.from_dict(e).to_dict()[table].get(key)
            except (_core.InvalidInputError, _core.ScenarioParseError):
                if default == REQ:
                    continue
                if not default.startswith(("required", "one of", "together")):
                    problems.append(f"{table}.{key} is documented with the default {default!r} but is required")
                continue
            if default == REQ:
                problems.append(f"{table}.{key} is documented as required but may be left out")
            value = _literal(default)
            if value is not None and filled is not None and filled != value:
                problems.append(f"{table}.{key}: documented default {default!r}, the parser fills in {filled!r}")
    return problems


def check() -> dict[str, set[str]]:
    have = accepted()
    problems = check_defaults()
    for table, keys in have.items():
        if table == "simulation":
            continue
        described = set(KEYS.get(table, {}))
        if keys - described:
            problems.append(f"[{table}] accepts {sorted(keys - described)}, not described in docs/_gen/toml_keys.py")
        if described - keys:
            problems.append(f"[{table}] no longer accepts {sorted(described - keys)}")
    for table in KEYS:
        if table not in have:
            problems.append(f"[{table}] is described but no longer a table")
    if problems:
        raise RuntimeError("the TOML reference is out of date: " + "; ".join(problems))
    return have


def _row(key, unit, default, meaning):
    return f"| `{key}` | {unit} | {default} | {meaning} |"


def table_md(table: str, have: dict[str, set[str]]) -> str:
    lines = [f"| key | unit | default | meaning |", "|---|---|---|---|"]
    if table == "simulation":
        defaults = _core.default_settings()
        for key, what in _core.settings_keys():
            d = defaults.get(key)
            d = "the file's name" if d is None and key == "name" else ("`" + _core.dumps_toml({"x": d}).split("=", 1)[1].strip() + "`" if d is not None else "–")
            unit = "s" if key in ("t_span", "h", "control_start") else "-"
            lines.append(_row(key, unit, d, what))
    else:
        for key, (unit, default, meaning) in KEYS[table].items():
            lines.append(_row(key, unit, default, meaning))
    return "\n".join(lines)


#: Which keys each physical range of the core (``_core.physical_ranges``) bounds.
RANGE_KEYS = {
    "hull length": "`thrusters.hull_length`",
    "hull beam": "`thrusters.hull_beam`",
    "draught": "`crossflow_drag.draft`",
    "water depth": "`pipe.water_depth`",
    "angle in radians": "`setpoint.headings`, `control.euler_reference`",
    "angle in degrees": "`pipe.lay_direction`, `thrusters.unit[i].angle`",
    "pipe departure angle": "`pipe.departure_angle`",
    "schedule time": "`setpoint.times`, `setpoint.start_time`, `current.times`",
    "controller time constant": "`control.tracking_time`",
    "vessel mass": "`vessel.mass`",
    "moment of inertia": "`vessel.inertia`",
    "gravity": "`vessel.gravity`",
    "water density": "`vessel.water_density`",
    "metacentric height": "`vessel.gm_transverse`, `vessel.gm_longitudinal`",
    "position": "`initial.position`, `control.position_reference`",
}


def ranges_md() -> str:
    """The physical ranges: the core's (asked of it) and those of the Python layer."""
    from phsplit import events

    rows = ["| range | unit | allowed | keys | why |", "|---|---|---|---|---|"]
    got = _core.physical_ranges()
    missing = {name for name, *_ in got} ^ set(RANGE_KEYS)
    if missing:
        raise SystemExit(f"toml_keys.py: RANGE_KEYS and the core's physical ranges differ: {sorted(missing)}")
    for name, unit, lo, hi, lo_closed, hi_closed, why in got:
        interval = f"{'[' if lo_closed else '('}{lo:g}, {hi:g}{']' if hi_closed else ')'}"
        rows.append(f"| {name} | {unit} | {interval} | {RANGE_KEYS[name]} | {why} |")
    sea_keys = {"tp": "`environment.waves.tp`", "direction": "`environment.waves` and `environment.wind`: "
                 "`direction`, `direction_towards`, `direction_from`", "height": "`environment.wind.height`",
                 "length": "`environment.wind.length` (with `ship_type`)"}
    for key, (lo, hi, unit, why) in sea.RANGES.items():
        rows.append(f"| sea: {key} | {unit} | [{lo:g}, {hi:g}] | {sea_keys[key]} | {why} |")
    rows += [
        f"| sweep size | cases | 1 to {batch.MAX_CASES} | `sweep.samples`, a grid's product | a larger sweep is a slip; split it |",
        "| sweep seed | - | 0 to 2⁶³ − 1 | `sweep.seed` | an integer, not a boolean |",
        f"| local workers | processes | 1 to {batch.MAX_WORKERS} | `phsplit sweep --workers` | more than any machine has cores |",
        f"| roll event | degrees | (0, {events.ANGLE_LIMITS['roll_beyond']:g}) | `phsplit.events.roll_beyond` | a roll beyond 180° is a roll the other way |",
        f"| pitch event | degrees | (0, {events.ANGLE_LIMITS['pitch_beyond']:g}) | `phsplit.events.pitch_beyond` | a ZYX pitch never exceeds 90° |",
    ]
    return "\n".join(rows)


def render() -> str:
    have = check()
    parts = []
    groups = [
        ("Scenario files", ["simulation", "environment.waves", "environment.wind"]),
        ("Vessel files (and any scenario, table by table)",
         ["vessel", "initial", "control", "external", "current", "damping_quadratic", "roll_damping", "crossflow_drag",
          "observer", "sensors", "pipe", "pipe.lumped_mass", "setpoint", "thrusters", "thrusters.unit", "waves", "wind"]),
        ("Sweep files", ["sweep"]),
    ]
    for title, tables in groups:
        parts.append(f"## {title}\n")
        for t in tables:
            name = ("[[thrusters.unit]]" if t == "thrusters.unit" else
                    '[pipe]` with `model = "lumped_mass"' if t == "pipe.lumped_mass" else f"[{t}]")
            parts.append(f"### `{name}`\n\nRead by {SOURCE[t]}.\n\n{table_md(t, have)}\n")
    parts.append("## Physical ranges\n\nA length, angle or time beyond what any vessel or sea has is a slip (a unit, a "
                 "digit) and is refused by name, with the range and the reason (`crates/phsplit-core/src/model/vessel/"
                 "params.rs`, `physical`; the sweep and event limits in `phsplit.batch` and `phsplit.events`). Besides, "
                 "booleans must be `true` or `false` (never a string or a number), a thruster's `kind` is required, "
                 "and waves from a direction a hydrodynamic dataset does not cover are refused, not extrapolated.\n\n"
                 + ranges_md() + "\n")
    return "\n".join(parts)
