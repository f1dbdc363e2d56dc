//! What the controller reports (`pid.rs`): with thrusters, the demand and what they deliver;
//! with a moving set point, the reference model's desired position and heading.

use super::super::{Frozen, Output};
use super::Pid;
use crate::model::vessel::state::VesselState;
use nalgebra::Vector3;

impl Pid {
    /// With thrusters, for the demand `tau` (surge, sway, yaw; body frame) at time `t`: the
    /// demand and what they deliver in surge, sway and yaw, each thruster's thrust, availability
    /// and angle, and the utilisation.
    pub(super) fn thruster_outputs(
        &self,
        fr: &Frozen,
        t: f64,
        tau: &Vector3<f64>,
        out: &mut Vec<Output>,
    ) {
        if let Some(all) = &self.thrusters {
            let th = all.at(t);
            let a = match fr.actuators.n {
                0 => th.allocate(tau),
                _ => th.allocate_limited(tau, &fr.actuators, t - fr.actuators.t),
            };
            for (k, (dof, unit)) in [("surge", "N"), ("sway", "N"), ("yaw", "N m")]
                .iter()
                .enumerate()
            {
                out.push(Output::new(
                    format!("commanded_{dof}"),
                    unit,
                    format!("controller's demand in {dof} (body frame)"),
                    a.commanded[k],
                ));
                out.push(Output::new(
                    format!("delivered_{dof}"),
                    unit,
                    format!("thrust delivered in {dof} (body frame)"),
                    a.delivered[k],
                ));
            }
            out.push(Output::new(
                "thrust_utilisation",
                "1",
                "largest thrust of a thruster over its limit",
                a.utilisation,
            ));
            for (i, u) in th.units.iter().enumerate() {
                out.push(Output::new(
                    format!("thruster{i}_thrust"),
                    "N",
                    format!("thrust of thruster {i} ({})", u.kind.name()),
                    a.thrust[i],
                ));
                out.push(Output::new(
                    format!("thruster{i}_available"),
                    "1",
                    format!("whether thruster {i} answers the allocation (0 once lost or stuck: its lost_at, stuck_at)"),
                    f64::from(u8::from(all.available(i, t))),
                ));
                out.push(Output::new(
                    format!("thruster{i}_angle"),
                    "degree",
                    format!("direction of the force of thruster {i} in the body's x-y plane"),
                    a.angle[i].to_degrees(),
                ));
            }
        }
    }

    /// With a moving set point: the reference model's desired position and heading, and the
    /// vessel's distance from the desired position, across and along the route.
    pub(super) fn setpoint_outputs(&self, s: &VesselState, t: f64, out: &mut Vec<Output>) {
        let Some(r) = &self.setpoint else {
            return;
        };
        let d = r.at(t);
        let (ex, ey) = (s.x.x - d.value[0], s.x.y - d.value[1]);
        let off = ex.hypot(ey);
        // Across and along the route (left of the route positive; along: ahead positive).
        let (cross, along) = match r.route_direction(t) {
            Some([ux, uy]) => (ux * ey - uy * ex, ux * ex + uy * ey),
            None => (off, 0.0),
        };
        for (name, unit, long_name, value) in [
            (
                "setpoint_x",
                "m",
                "desired position x from the reference model (spatial)",
                d.value[0],
            ),
            (
                "setpoint_y",
                "m",
                "desired position y from the reference model (spatial)",
                d.value[1],
            ),
            (
                "setpoint_heading",
                "rad",
                "desired heading (yaw) from the reference model",
                d.value[5],
            ),
            (
                "setpoint_offset",
                "m",
                "horizontal distance of the vessel from the desired position",
                off,
            ),
            (
                "route_cross_track",
                "m",
                "vessel's offset across the route from the desired position (left positive)",
                cross,
            ),
            (
                "route_along_track",
                "m",
                "vessel's offset along the route from the desired position (ahead positive)",
                along,
            ),
        ] {
            out.push(Output::new(name, unit, long_name, value));
        }
    }
}
