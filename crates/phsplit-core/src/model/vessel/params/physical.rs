//! The physical ranges, in one place (listed in docs/reference/toml.md). Each is wide enough
//! for every vessel and sea, and narrow enough to catch a value in the wrong unit.

use super::Physical;

/// A hull's length (m): the longest ships ever built are under 460 m.
pub const HULL_LENGTH: Physical = Physical {
    lo: 0.0,
    hi: 500.0,
    lo_closed: false,
    hi_closed: true,
    why: "no hull is longer than 500 m",
};
/// A hull's beam (m): the widest hulls (crane vessels, semi-submersibles) are under 130 m.
pub const HULL_BEAM: Physical = Physical {
    lo: 0.0,
    hi: 150.0,
    lo_closed: false,
    hi_closed: true,
    why: "no hull is wider than 150 m",
};
/// A draught (m): the deepest-draught ships float at under 35 m.
pub const DRAFT: Physical = Physical {
    lo: 0.0,
    hi: 40.0,
    lo_closed: false,
    hi_closed: true,
    why: "no ship draws more than 40 m",
};
/// A water depth (m): the deepest ocean (the Challenger Deep) is under 11 km.
pub const WATER_DEPTH: Physical = Physical {
    lo: 0.0,
    hi: 11000.0,
    lo_closed: false,
    hi_closed: true,
    why: "no sea is deeper than 11000 m",
};
/// A heading or attitude angle in radians: within a full turn either way. A value beyond it
/// is a heading in degrees.
pub const ANGLE_RAD: Physical = Physical {
    lo: -std::f64::consts::TAU,
    hi: std::f64::consts::TAU,
    lo_closed: true,
    hi_closed: true,
    why: "radians, within a full turn (±2π); a larger value is an angle in degrees",
};
/// A direction in degrees: within a full turn either way.
pub const ANGLE_DEG: Physical = Physical {
    lo: -360.0,
    hi: 360.0,
    lo_closed: true,
    hi_closed: true,
    why: "degrees, within a full turn either way",
};
/// A pipe's departure angle from the horizontal (degrees): below 5° the catenary's
/// suspended span is over 20 times the water depth (and its tension beyond any lay
/// vessel's); 90° is a vertical pipe, whose lay direction is undefined.
pub const DEPARTURE_ANGLE: Physical = Physical {
    lo: 5.0,
    hi: 90.0,
    lo_closed: true,
    hi_closed: false,
    why: "a pipe flatter than 5° spans over 20 water depths",
};
/// A time of an operation's schedule (s): within about 30 years of t = 0.
pub const TIME: Physical = Physical {
    lo: -1e9,
    hi: 1e9,
    lo_closed: true,
    hi_closed: true,
    why: "within 1e9 s (about 30 years) of t = 0",
};
/// A controller's time constant (s): positive, at most a day (DP integrals act in minutes).
pub const TRACKING_TIME: Physical = Physical {
    lo: 0.0,
    hi: 86400.0,
    lo_closed: false,
    hi_closed: true,
    why: "a controller's time constant is positive and at most a day",
};
/// A vessel's mass (kg): the largest ships ever built displaced under 7e8 kg.
pub const MASS: Physical = Physical {
    lo: 0.0,
    hi: 1e9,
    lo_closed: false,
    hi_closed: true,
    why: "no vessel displaces more than 1e9 kg",
};
/// A vessel's moment of inertia (kg m²): the largest ship's yaw inertia is about 1e13.
pub const INERTIA: Physical = Physical {
    lo: 0.0,
    hi: 1e14,
    lo_closed: false,
    hi_closed: true,
    why: "ten times the largest ship's yaw inertia",
};
/// The acceleration of gravity (m/s²): 9.78 at the equator to 9.83 at the poles.
pub const GRAVITY: Physical = Physical {
    lo: 9.7,
    hi: 9.9,
    lo_closed: true,
    hi_closed: true,
    why: "the sea is on Earth, where gravity is 9.78 to 9.83 m/s^2",
};
/// The water's density (kg/m³): fresh water 1000, sea water about 1025, the Dead Sea 1240.
pub const WATER_DENSITY: Physical = Physical {
    lo: 950.0,
    hi: 1250.0,
    lo_closed: true,
    hi_closed: true,
    why: "fresh water is 1000 kg/m^3, sea water about 1025, the saltiest lake 1240",
};
/// A metacentric height (m): longitudinal ones are of the order of the hull's length.
pub const METACENTRIC_HEIGHT: Physical = Physical {
    lo: 0.0,
    hi: 2000.0,
    lo_closed: false,
    hi_closed: true,
    why: "a metacentric height is of the order of the hull's beam or length, under 2 km",
};
/// A position in the spatial frame (m): within 10,000 km of its origin.
pub const POSITION: Physical = Physical {
    lo: -1e7,
    hi: 1e7,
    lo_closed: true,
    hi_closed: true,
    why: "within 10000 km of the spatial frame's origin (a quarter of the Earth's circumference)",
};

/// Every named range, for the documentation.
pub const ALL: [(&str, &str, Physical); 15] = [
    ("hull length", "m", HULL_LENGTH),
    ("hull beam", "m", HULL_BEAM),
    ("draught", "m", DRAFT),
    ("water depth", "m", WATER_DEPTH),
    ("angle in radians", "rad", ANGLE_RAD),
    ("angle in degrees", "degrees", ANGLE_DEG),
    ("pipe departure angle", "degrees", DEPARTURE_ANGLE),
    ("schedule time", "s", TIME),
    ("controller time constant", "s", TRACKING_TIME),
    ("vessel mass", "kg", MASS),
    ("moment of inertia", "kg m^2", INERTIA),
    ("gravity", "m/s^2", GRAVITY),
    ("water density", "kg/m^3", WATER_DENSITY),
    ("metacentric height", "m", METACENTRIC_HEIGHT),
    ("position", "m", POSITION),
];
