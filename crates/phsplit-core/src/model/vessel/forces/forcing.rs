//! The forcing of flow S2 ([`Forcing`]): what the components' non-affine or time-dependent
//! parts add at one time and state (`mod.rs`, "Forcing").

use super::{Sys, Z3};
use crate::solve::INLINE_ACCOUNTS;
use nalgebra::Vector3;

/// The forcing of flow S2 at one time and block state: what the components' non-affine or
/// time-dependent parts add to the fields of the two block systems, and, per account, the
/// forces they book (the first [`INLINE_ACCOUNTS`] inline, any further on the heap, as in
/// [`crate::solve::Work`]).
#[derive(Debug, Clone)]
pub struct Forcing {
    /// Added to `(u', v', w')` of each block system.
    pub g: [Z3; 2],
    /// The booked force on the momentum of each system, per account.
    booked: [[Vector3<f64>; 2]; INLINE_ACCOUNTS],
    /// The same for accounts `INLINE_ACCOUNTS..`, as far as any was booked.
    spill: Vec<[Vector3<f64>; 2]>,
    /// First account of the component being evaluated.
    pub(crate) base: usize,
    /// Added to the rates of the components' own states ([`super::super::VesselState::own`]'s
    /// layout; empty, or as far as any was added: the rest adds nothing).
    pub own: Vec<f64>,
    /// Where the own states of the component being evaluated start in that layout.
    pub(crate) own_base: usize,
}

impl Forcing {
    pub(crate) fn new() -> Self {
        Self {
            g: [[Vector3::zeros(); 3]; 2],
            booked: [[Vector3::zeros(); 2]; INLINE_ACCOUNTS],
            spill: Vec::new(),
            base: 0,
            own: Vec::new(),
            own_base: 0,
        }
    }
    /// Add a force on the momentum of `sys`, booked to the component's account `account` (its
    /// index in [`Force::accounts`]), or to none (a conservative exchange between stores of H).
    #[inline]
    pub fn force(&mut self, sys: Sys, account: Option<usize>, f: Vector3<f64>) {
        self.g[sys as usize][0] += f;
        if let Some(k) = account {
            let k = self.base + k;
            match self.booked.get_mut(k) {
                Some(b) => b[sys as usize] += f,
                None => self.spilled(k - INLINE_ACCOUNTS)[sys as usize] += f,
            }
        }
    }
    #[cold]
    fn spilled(&mut self, j: usize) -> &mut [Vector3<f64>; 2] {
        if j >= self.spill.len() {
            self.spill.resize(j + 1, [Vector3::zeros(); 2]);
        }
        &mut self.spill[j]
    }
    /// No forcing again.
    #[inline]
    pub(crate) fn clear(&mut self) {
        self.g = [[Vector3::zeros(); 3]; 2];
        self.booked = [[Vector3::zeros(); 2]; INLINE_ACCOUNTS];
        self.spill
            .iter_mut()
            .for_each(|b| *b = [Vector3::zeros(); 2]);
        self.own.fill(0.0);
    }
    /// Add to the rate of the third state of `sys` (an integral state).
    pub fn rate_w(&mut self, sys: Sys, r: Vector3<f64>) {
        self.g[sys as usize][2] += r;
    }
    /// Add `r` to the rate of the component's own state `i` (its index in its
    /// [`super::Force::own_states`]).
    pub fn rate_own(&mut self, i: usize, r: f64) {
        let k = self.own_base + i;
        if k >= self.own.len() {
            self.own.resize(k + 1, 0.0);
        }
        self.own[k] += r;
    }
    /// The forcing's part on own state `k` of the layout (zero where none was added).
    pub fn own_part(&self, k: usize) -> f64 {
        self.own.get(k).copied().unwrap_or(0.0)
    }
    /// The force booked to account `k` on the momentum of each system.
    #[inline]
    pub fn booked(&self, k: usize) -> [Vector3<f64>; 2] {
        match self.booked.get(k) {
            Some(b) => *b,
            None => self
                .spill
                .get(k - INLINE_ACCOUNTS)
                .copied()
                .unwrap_or([Vector3::zeros(); 2]),
        }
    }
}
