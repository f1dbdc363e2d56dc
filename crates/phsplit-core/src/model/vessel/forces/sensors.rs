//! The position and heading sensors the observer reads (docs/model.md §5.20, `[sensors]`): a
//! GNSS receiver's horizontal position and a gyrocompass's heading, each sampled at its rate,
//! with a constant bias and white noise from a seed, and held between samples (zero-order
//! hold), as a DP system's sensors deliver them (Fossen 2021, §13.1; Sørensen, *A survey of
//! dynamic positioning control systems*, Annu. Rev. Control 35 (2011) 123–136, §3).
//!
//! Keys: `gnss_rate`, `gyro_rate` (Hz, required: a sensor has no default rate), `gnss_noise`
//! (m, standard deviation of each horizontal axis; default 0), `gnss_bias` (2 numbers, m,
//! spatial x and y; default 0), `gyro_noise` (rad, standard deviation; default 0), `gyro_bias`
//! (rad; default 0), `gnss_dropout`, `gyro_dropout` (rows `[start, end]`, s: the sensor delivers
//! nothing from `start` to `end`), `seed` (integer ≥ 0; default 0).
//!
//! Lever arm and MRU: `gnss_antenna` (3 numbers, m, body frame from the body origin; default the
//! origin) places the receiver's antenna, which moves with the hull's roll and pitch: it
//! measures `x + Q r_a` (the position of a point fixed in the body, docs/model.md §2.1). The DP
//! system refers the fix to the body origin with the attitude it measures, `x̂ = p_a − R(Θ̃) r_a`,
//! `Θ̃` the motion reference unit's (MRU's) roll and pitch and the gyro's last heading (the
//! standard lever-arm correction of a DP system's position references: Sørensen, Annu. Rev.
//! Control 35 (2011) §3). The MRU is read at each GNSS
//! sample (an MRU samples at 10–100 Hz, far above a GNSS's 1–10 Hz) with `mru_noise` (rad,
//! standard deviation of roll and of pitch; default 0) and `mru_bias` (2 numbers, rad, roll and
//! pitch; default 0). A perfect MRU and gyro cancel the lever arm exactly; what is left is the
//! arm times their errors (a 20 m mast and a 0.01 rad roll error: 0.2 m).
//!
//! Sampling: at the end of every step at time `t` the sensor takes a sample if a sample
//! instant `k / rate` has passed since its last one, `k = ⌊t · rate⌋`: so the samples are the
//! state at the step ends, exactly at the instants when the sample period is a whole number of
//! steps, else at the first step end after each instant. The sample is the true value plus the
//! bias plus the noise of sample `k`, a normal deviate drawn from `(seed, sensor, k)` alone
//! (SplitMix64, Steele, Lea & Flood 2014, and the Box–Muller transform), so a run cut into
//! parts, a rerun and an FMU draw the same numbers.
//!
//! Dropout: while a sensor is out its measurement is marked invalid and the observer runs on
//! its model alone (no injection from that sensor: dead reckoning); when it returns, it samples
//! at once. The held values are own states of the controller (not energy: they store nothing of
//! H); what the observer does with them is in `observer.rs`.

use crate::error::Error;
use crate::model::vessel::params::{Params, Physical, Range};
use nalgebra::{Matrix3, Vector3};
use toml::Value;

const T: &str = "sensors";

/// Own states of the sensors, after the observer's: the held measurement `(x, y, ψ)`, each
/// sensor's validity (1 or 0), and the index of each sensor's last sample.
pub const N: usize = 7;
const VALID_GNSS: usize = 3;
const VALID_GYRO: usize = 4;
const K_GNSS: usize = 5;
const K_GYRO: usize = 6;

const RATE: Physical = Physical {
    lo: 0.0,
    hi: 1000.0,
    lo_closed: false,
    hi_closed: true,
    why: "a position or heading sensor samples at most 1000 times a second",
};
const POSITION_NOISE: Physical = Physical {
    lo: 0.0,
    hi: 100.0,
    lo_closed: true,
    hi_closed: true,
    why: "a position fix worse than 100 m is no DP sensor's",
};
const POSITION_BIAS: Physical = Physical {
    lo: -1000.0,
    hi: 1000.0,
    lo_closed: true,
    hi_closed: true,
    why: "a position bias beyond 1 km is no DP sensor's",
};
const HEADING_NOISE: Physical = Physical {
    lo: 0.0,
    ..HEADING_ERROR
};
const HEADING_ERROR: Physical = Physical {
    lo: -0.5,
    hi: 0.5,
    lo_closed: true,
    hi_closed: true,
    why:
        "radians; a heading error beyond 0.5 rad (29°) is no gyrocompass's, or an angle in degrees",
};

#[derive(Debug, Clone, PartialEq)]
struct Sensor {
    rate: f64,
    dropout: Vec<(f64, f64)>,
}

impl Sensor {
    fn out_at(&self, t: f64) -> bool {
        self.dropout.iter().any(|&(a, b)| t >= a && t < b)
    }
    /// At time `t`, with its last sample's index `last` and validity `valid` (1 or 0): the
    /// index of the sample due now, if one is (a new instant passed, or back from a dropout),
    /// and whether it delivers.
    /// The first sample instant `k / rate` or dropout edge after `t` (s).
    fn next_event(&self, t: f64) -> f64 {
        let k = (t * self.rate + 1e-9).floor() + 1.0;
        let edges = self.dropout.iter().flat_map(|&(a, b)| [a, b]);
        edges.filter(|&e| e > t).fold(k / self.rate, f64::min)
    }
    fn due(&self, t: f64, last: f64, valid: f64) -> (Option<f64>, bool) {
        let k = (t * self.rate + 1e-9).floor();
        let delivers = !self.out_at(t);
        (
            (delivers && (k != last || valid == 0.0)).then_some(k),
            delivers,
        )
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Sensors {
    gnss: Sensor,
    gyro: Sensor,
    gnss_noise: f64,
    gnss_bias: [f64; 2],
    gyro_noise: f64,
    gyro_bias: f64,
    /// The GNSS antenna (m, body frame) and the MRU's roll and pitch errors (rad).
    antenna: Vector3<f64>,
    mru_noise: f64,
    mru_bias: [f64; 2],
    seed: u64,
}

/// Where a GNSS antenna may sit: within a large ship's half length of the body origin.
const ANTENNA: Physical = Physical {
    lo: -250.0,
    hi: 250.0,
    lo_closed: true,
    hi_closed: true,
    why: "m from the body origin; no hull puts its antenna farther",
};
const ATTITUDE_ERROR: Physical = Physical {
    lo: -0.1,
    hi: 0.1,
    lo_closed: true,
    hi_closed: true,
    why: "radians; an MRU's roll or pitch error beyond 0.1 rad (5.7°) is no MRU's, or an angle in degrees",
};
const ATTITUDE_NOISE: Physical = Physical {
    lo: 0.0,
    ..ATTITUDE_ERROR
};

fn dropout(p: &mut Params, key: &str) -> crate::Result<Vec<(f64, f64)>> {
    let Some(rows) = p.rows(
        T,
        key,
        2,
        "s",
        Range::Physical(&super::super::params::physical::TIME),
    )?
    else {
        return Ok(Vec::new());
    };
    let mut last = f64::NEG_INFINITY;
    let mut out = Vec::with_capacity(rows.len());
    for (i, r) in rows.iter().enumerate() {
        if r[1] <= r[0] {
            return Err(Error::InvalidInput(format!(
                "sensors.{key}[{i}] = [{}, {}]: a dropout is [start, end] with end > start (s)",
                r[0], r[1]
            )));
        }
        if r[0] < last {
            return Err(Error::InvalidInput(format!(
                "sensors.{key}[{i}] starts at {} s, before the dropout above it ends ({last} s): give the dropouts in time order, without overlaps",
                r[0]
            )));
        }
        last = r[1];
        out.push((r[0], r[1]));
    }
    Ok(out)
}

/// Two numbers of `[sensors]` (`what`: their unit and meaning), each in `range`; zero if absent.
fn pair(
    p: &mut Params,
    key: &str,
    what: &str,
    range: &'static Physical,
) -> crate::Result<[f64; 2]> {
    let unit = what.split(',').next().unwrap_or(what);
    match p.rows(T, key, 1, unit, Range::Physical(range))? {
        None => Ok([0.0; 2]),
        Some(r) if r.len() == 2 => Ok([r[0][0], r[1][0]]),
        Some(r) => Err(Error::InvalidInput(format!(
            "sensors.{key} must be 2 numbers ({what}), got {} entries",
            r.len()
        ))),
    }
}

/// Table `[sensors]` (module documentation), or `None` without it.
pub fn read(p: &mut Params) -> crate::Result<Option<Sensors>> {
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    // Both rates read before either is found missing, so that neither is taken for a
    // misspelling of the other.
    let gnss_rate = p.opt_f64(T, "gnss_rate", "Hz", Range::Physical(&RATE))?;
    let gyro_rate = p.opt_f64(T, "gyro_rate", "Hz", Range::Physical(&RATE))?;
    let (Some(gnss_rate), Some(gyro_rate)) = (gnss_rate, gyro_rate) else {
        let key = if gnss_rate.is_none() {
            "gnss_rate"
        } else {
            "gyro_rate"
        };
        return Err(p.missing(T, key, "Hz: the sensor's sample rate"));
    };
    let gnss_noise = p
        .opt_f64(T, "gnss_noise", "m", Range::Physical(&POSITION_NOISE))?
        .unwrap_or(0.0);
    let gyro_noise = p
        .opt_f64(T, "gyro_noise", "rad", Range::Physical(&HEADING_NOISE))?
        .unwrap_or(0.0);
    let gyro_bias = p
        .opt_f64(T, "gyro_bias", "rad", Range::Physical(&HEADING_ERROR))?
        .unwrap_or(0.0);
    let gnss_bias = pair(p, "gnss_bias", "m, spatial x and y", &POSITION_BIAS)?;
    let antenna: Vector3<f64> = p
        .vec3(
            T,
            "gnss_antenna",
            Some([0.0; 3]),
            "m, body frame",
            Range::Physical(&ANTENNA),
        )?
        .into();
    let mru_noise = p
        .opt_f64(T, "mru_noise", "rad", Range::Physical(&ATTITUDE_NOISE))?
        .unwrap_or(0.0);
    let mru_bias = pair(p, "mru_bias", "rad, roll and pitch", &ATTITUDE_ERROR)?;
    if antenna == Vector3::zeros() && (mru_noise != 0.0 || mru_bias != [0.0; 2]) {
        return Err(Error::InvalidInput(
            "sensors.mru_noise and mru_bias describe the MRU that refers the GNSS fix to the body origin; with the antenna at the origin nothing reads it: give sensors.gnss_antenna (m, body frame), or remove them".into(),
        ));
    }
    let seed = match p.take_raw(T, "seed")? {
        None => 0,
        Some(Value::Integer(i)) if i >= 0 => i as u64,
        Some(other) => {
            return Err(Error::InvalidInput(format!(
                "sensors.seed must be a whole number ≥ 0, got {} {other}",
                other.type_str()
            )))
        }
    };
    p.record_value(T, "seed", Value::Integer(seed as i64));
    let gnss = Sensor {
        rate: gnss_rate,
        dropout: dropout(p, "gnss_dropout")?,
    };
    let gyro = Sensor {
        rate: gyro_rate,
        dropout: dropout(p, "gyro_dropout")?,
    };
    Ok(Some(Sensors {
        gnss,
        gyro,
        gnss_noise,
        gnss_bias,
        gyro_noise,
        gyro_bias,
        antenna,
        mru_noise,
        mru_bias,
        seed,
    }))
}

/// SplitMix64's output for `x` (Steele, Lea & Flood, OOPSLA 2014).
fn splitmix(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// A standard normal deviate from `(seed, stream, k)` (Box–Muller on two uniforms in (0, 1)).
fn normal(seed: u64, stream: u64, k: f64) -> f64 {
    let base =
        splitmix(seed ^ splitmix(stream.wrapping_mul(0xD6E8_FEB8_6659_FD93) ^ (k as i64 as u64)));
    let u = |x: u64| ((x >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
    let (u1, u2) = (u(splitmix(base)), u(splitmix(base ^ 0xA5A5_A5A5_A5A5_A5A5)));
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

impl Sensors {
    /// The next sample instant or dropout edge of either sensor after `t` (s).
    pub fn next_event(&self, t: f64) -> f64 {
        self.gnss.next_event(t).min(self.gyro.next_event(t))
    }

    /// The own states' names, units and long names.
    pub fn states() -> [(&'static str, &'static str, &'static str); N] {
        [
            (
                "measured_x",
                "m",
                "position x the GNSS receiver last delivered (spatial)",
            ),
            (
                "measured_y",
                "m",
                "position y the GNSS receiver last delivered (spatial)",
            ),
            (
                "measured_heading",
                "rad",
                "heading the gyrocompass last delivered",
            ),
            (
                "gnss_valid",
                "1",
                "1 while the GNSS receiver delivers, 0 during its dropouts",
            ),
            (
                "gyro_valid",
                "1",
                "1 while the gyrocompass delivers, 0 during its dropouts",
            ),
            (
                "gnss_sample",
                "1",
                "index of the GNSS receiver's last sample (time × rate)",
            ),
            (
                "gyro_sample",
                "1",
                "index of the gyrocompass's last sample (time × rate)",
            ),
        ]
    }

    /// Before the run: the true position and heading, marked not yet delivered (validity 0),
    /// so that the run's start ([`Self::update`] there) takes the first samples.
    pub fn init(&self, pos: &Vector3<f64>, psi: f64, x: &mut [f64]) {
        x.fill(0.0);
        x[0] = pos.x;
        x[1] = pos.y;
        x[2] = psi;
    }

    /// At time `t`, with the vessel at position `pos`, attitude `q` and heading `psi`: take the
    /// samples due and mark the sensors out or in
    /// (module documentation). The gyro samples first, so that the GNSS fix of the same
    /// instant is referred to the origin with its heading.
    pub fn update(&self, t: f64, pos: &Vector3<f64>, q: &Matrix3<f64>, psi: f64, x: &mut [f64]) {
        let (k, delivers) = self.gyro.due(t, x[K_GYRO], x[VALID_GYRO]);
        if let Some(k) = k {
            x[2] = psi + self.gyro_bias + self.gyro_noise * normal(self.seed, 3, k);
            x[K_GYRO] = k;
        }
        x[VALID_GYRO] = f64::from(u8::from(delivers));
        let (k, delivers) = self.gnss.due(t, x[K_GNSS], x[VALID_GNSS]);
        if let Some(k) = k {
            let fix = pos + self.lever(q, x[2], k);
            x[0] = fix.x + self.gnss_bias[0] + self.gnss_noise * normal(self.seed, 1, k);
            x[1] = fix.y + self.gnss_bias[1] + self.gnss_noise * normal(self.seed, 2, k);
            x[K_GNSS] = k;
        }
        x[VALID_GNSS] = f64::from(u8::from(delivers));
    }

    /// What the lever arm leaves in the GNSS sample `k` referred to the origin: the antenna's
    /// true offset `Q r_a` less the one the DP system computes, `R(φ̃, θ̃, ψ̃) r_a`, with the
    /// MRU's roll and pitch at the sample and the gyro's heading `psi_measured`.
    fn lever(&self, q: &Matrix3<f64>, psi_measured: f64, k: f64) -> Vector3<f64> {
        if self.antenna == Vector3::zeros() {
            return Vector3::zeros();
        }
        let e = crate::lie::so3::euler_zyx(q);
        let measured = Vector3::new(
            e.x + self.mru_bias[0] + self.mru_noise * normal(self.seed, 4, k),
            e.y + self.mru_bias[1] + self.mru_noise * normal(self.seed, 5, k),
            psi_measured,
        );
        q * self.antenna - crate::lie::so3::from_euler_zyx(&measured) * self.antenna
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_deviates_are_standard_normal_and_reproducible() {
        let n = 200_000;
        let xs: Vec<f64> = (0..n).map(|k| normal(7, 1, k as f64)).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        assert!(mean.abs() < 0.01, "{mean}");
        assert!((var - 1.0).abs() < 0.01, "{var}");
        let fourth = xs.iter().map(|x| x.powi(4)).sum::<f64>() / n as f64;
        assert!((fourth - 3.0).abs() < 0.06, "{fourth}");
        assert_eq!(normal(7, 1, 12.0), normal(7, 1, 12.0));
        assert_ne!(normal(7, 1, 12.0), normal(7, 2, 12.0));
        assert_ne!(normal(7, 1, 12.0), normal(8, 1, 12.0));
    }
}
