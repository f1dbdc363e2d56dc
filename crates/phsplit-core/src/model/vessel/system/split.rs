//! The vessel as a split model: its flows S1 and S2 (the components' own flows nested in S2) and
//! what merges and which orders they provide (docs/model.md §3).

use super::super::state::VesselState;
use super::{LinearFlow, MagnusOrder, VesselSystem, MAX_SUBFLOW_ORDER};
use crate::error::{Error, Result};
use crate::methods::Flow;
use crate::solve::{SplitModel, Work};

impl SplitModel for VesselSystem<'_> {
    /// Flow S1 is exact for a mass matrix of the paper's form (the free rigid body's elliptic
    /// flow), not for Kirchhoff's collocation; flow S2 is exact when it is the matrix
    /// exponential (no forcing, `linear_flow = "exact"`), not when it is collocated. Nothing
    /// merges with rate-limited thrusters.
    fn merges_exactly(&self, flow: Flow) -> bool {
        // Rate-limited thrusters write their memory at every step's end (`Model::end_step`):
        // a sub-step merged across the boundary would skip it.
        if self.actuators > 0 {
            return false;
        }
        match flow {
            Flow::S1 => self.vessel.body.kirchhoff.is_none(),
            Flow::S2 => {
                !self.forced && self.linear == LinearFlow::Exact && self.own_flowing.is_empty()
            }
        }
    }
    fn revisits_states(&self, revisits: bool) {
        // Adaptive steps come back to a step's start and midpoint: keep the assemblies made
        // there (`memo.rs`); fixed steps keep the last only (more would only spread the
        // memory a step touches).
        self.keep_assemblies(if revisits { super::memo::KEPT } else { 1 });
    }
    fn supports_order(&self, order: usize) -> Result<()> {
        if order > 2 && !self.own_flowing.is_empty() {
            return Err(Error::InvalidInput(format!(
                "the method (simulation.method, method=) is a composition of order {order}, which needs sub-flows of order {order}; the lumped-mass pipe's flow is nested in flow S2 by Strang's rule, of order 2: use lie or sp2 (or pipe.model = \"catenary\")"
            )));
        }
        if let Some(fixed) = self.linear.fixed_order().filter(|&o| o < order) {
            return Err(Error::InvalidInput(format!(
                "linear_flow = '{}' integrates flow S2 to order {fixed}, below the method's order {order} (simulation.method, method=), which would lose its order: take linear_flow = 'gauss' (the method's order), 'gauss6' or 'auto'",
                self.linear.name()
            )));
        }
        if order > MAX_SUBFLOW_ORDER {
            return Err(Error::InvalidInput(format!(
                "the method (simulation.method, method=) is a composition of order {order}, which needs sub-flows of order {order}; the vessel's flows provide order {MAX_SUBFLOW_ORDER} at most (Magnus 6, Gauss collocation with 3 stages)"
            )));
        }
        Ok(())
    }
    fn flow(
        &self,
        which: Flow,
        h: f64,
        t_step: f64,
        t: f64,
        order: usize,
        ledger: bool,
        s: &mut VesselState,
    ) -> Work {
        match which {
            Flow::S1 => {
                let mo = MagnusOrder::for_order(order).expect("checked by supports_order");
                self.flow_s1(s, h, mo);
                Work::default()
            }
            Flow::S2 => {
                let stages = self.linear.stages(order);
                let on = self.control_on(t_step);
                if self.own_flowing.is_empty() {
                    return self.flow_s2(s, h, t, on, ledger, stages);
                }
                // The components' own flows nested by Strang's rule, S2(h/2) S3(h) S2(h/2):
                // one own flow per sub-step (their Newton iterations cost more than S2).
                let mut w = self.flow_s2(s, 0.5 * h, t, on, ledger, stages);
                w += &self.own_flows(s, h, on);
                if !s.p.x.is_finite() {
                    return w;
                }
                w += &self.flow_s2(s, 0.5 * h, t + 0.5 * h, on, ledger, stages);
                w
            }
        }
    }
}
