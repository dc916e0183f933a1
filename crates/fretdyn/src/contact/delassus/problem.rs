//! The tangential problem's workspace ([`TangentialProblem`]): the closed contacts, the rows
//! of `L` and `A⁻¹Lᵀ`, the assembly of `H = L A⁻¹ Lᵀ` and `b`, and the accessors the solvers
//! read them by (THEORY §4.2; the module documentation of [`super`] states the problem).

use std::cell::Cell;

use nalgebra::{Matrix2, Vector2, Vector3};

use crate::contact::friction::DiagonalBlock;
use crate::numerics::{Lanes, Portable, map3};
use crate::structure::modal::thirds;

/// One closed contact in the tangential problem.
#[derive(Debug, Clone, Copy, Default)]
pub struct Slot {
    /// Index of the contact in the model.
    pub contact: usize,
    /// Stick threshold `μ_s R_N`.
    pub s_static: f64,
    /// Slip force `μ_d R_N`.
    pub s_dynamic: f64,
}

/// Workspace of the tangential problem for the contacts closed at this step.
#[derive(Debug, Clone)]
pub struct TangentialProblem {
    pub(super) p: usize,
    pub(super) slots: Vec<Slot>,
    /// `L` rows, stored per contact (rows `2c`, `2c + 1` of contact `c`), p values each.
    l: Vec<f64>,
    /// `A⁻¹ Lᵀ` stored as rows: `al[r] = A⁻¹ ∘ l[r]`, same layout.
    al: Vec<f64>,
    /// Contacts whose rows are computed once ([`fix_rows`](Self::fix_rows)).
    fixed: Vec<bool>,
    /// `H` between fixed contacts, indexed by contact rows, row stride `2 * capacity`.
    h_fixed: Vec<f64>,
    /// `H` of the closed contacts, indexed by slot rows, row stride `2 * capacity`.
    h: Vec<f64>,
    /// Right-hand side `b`, by slot rows.
    pub(super) b: Vec<f64>,
    /// The diagonal blocks prepared for their local solves: `H_cc` of fixed contact `c` at
    /// `c`, prepared once ([`Self::fix_rows`]); `H_kk` of the other slots at `contacts + k`,
    /// prepared by [`Self::assemble`].
    blocks: Vec<DiagonalBlock>,
    /// Per slot, the index of its diagonal block in `blocks` ([`Self::diagonal_block`]).
    block_of: Vec<usize>,
    /// Per slot, the Newton start of its exact slip solve within the step
    /// ([`crate::contact::friction::local_solve_block`]); reset by [`Self::assemble`].
    newton: Vec<Cell<f64>>,
    /// Per slot, the right-hand side `c_k` of its local solve in the last Gauss–Seidel sweep
    /// and the change of its `λ_k` in that sweep ([`Self::record_sweep`]).
    pub(super) sweep: Vec<Cell<[Vector2<f64>; 2]>>,
    stride: usize,
    /// The closed contacts of the last singularity test whose `H` was made of fixed rows
    /// only, and its answer ([`Self::is_singular`]).
    pub(super) singular_for: Vec<usize>,
    pub(super) singular: Option<bool>,
    /// The closed contacts whose `H`, made of fixed rows only, is in `h` (empty: none):
    /// [`Self::assemble`] gathers it again only when they change.
    h_for: Vec<usize>,
    /// Whether every slot's rows are fixed (kept by [`Self::clear`] and [`Self::push_with`]).
    pub(super) all_fixed: bool,
    /// Whether a contact with fixed rows has a singular block ([`DiagonalBlock::is_singular`];
    /// set by [`Self::fix_rows`]).
    fixed_singular: bool,
    /// Whether a slot whose rows are not fixed has a singular block this step (set by
    /// [`Self::assemble`], reset by [`Self::clear`]).
    moving_singular: bool,
}

impl TangentialProblem {
    /// Workspace for up to `contacts` closed contacts on `p` modes; contact indices of the
    /// slots must be below `contacts`.
    pub fn new(p: usize, contacts: usize) -> Self {
        let rows = 2 * contacts;
        Self {
            p,
            slots: Vec::with_capacity(contacts),
            l: vec![0.0; rows * p],
            al: vec![0.0; rows * p],
            fixed: vec![false; contacts],
            h_fixed: vec![0.0; rows * rows],
            h: vec![0.0; rows * rows],
            b: vec![0.0; rows],
            blocks: vec![DiagonalBlock::default(); 2 * contacts],
            block_of: Vec::with_capacity(contacts),
            newton: vec![Cell::new(f64::NAN); contacts],
            sweep: vec![Cell::new([Vector2::zeros(); 2]); contacts],
            stride: rows,
            singular_for: Vec::with_capacity(contacts),
            singular: None,
            h_for: Vec::with_capacity(contacts),
            all_fixed: true,
            fixed_singular: false,
            moving_singular: false,
        }
    }

    /// Declares that `contact` always has the tangent basis `tangents`: its rows, and its
    /// blocks of `H` with the other fixed contacts, are computed now, once. `apply_a_inv`
    /// computes `A⁻¹ l` (see [`push_with`](Self::push_with)).
    pub fn fix_rows(
        &mut self,
        contact: usize,
        tangents: &[Vector3<f64>; 2],
        rows: &[f64],
        apply_a_inv: impl Fn(&[f64], &mut [f64]),
    ) {
        self.fixed[contact] = false;
        self.singular = None;
        self.h_for.clear();
        self.compute_rows(contact, tangents, rows, apply_a_inv);
        self.fixed[contact] = true;
        self.all_fixed = self.slots.iter().all(|s| self.fixed[s.contact]);
        let p = self.p;
        for other in 0..self.fixed.len() {
            if !self.fixed[other] {
                continue;
            }
            for a in 0..2 {
                for b in 0..2 {
                    let (r, c) = (2 * contact + a, 2 * other + b);
                    let v = crate::structure::modal::dot(
                        &self.l[r * p..(r + 1) * p],
                        &self.al[c * p..(c + 1) * p],
                    );
                    self.h_fixed[r * self.stride + c] = v;
                    self.h_fixed[c * self.stride + r] = v;
                }
            }
        }
        let (r, st) = (2 * contact, self.stride);
        let h = Matrix2::new(
            self.h_fixed[r * st + r],
            self.h_fixed[r * st + r + 1],
            self.h_fixed[(r + 1) * st + r],
            self.h_fixed[(r + 1) * st + r + 1],
        );
        self.blocks[contact] = DiagonalBlock::new(h);
        self.fixed_singular =
            (0..self.fixed.len()).any(|c| self.fixed[c] && self.blocks[c].is_singular());
    }

    /// Whether a closed contact's diagonal block may be singular this step
    /// ([`DiagonalBlock::is_singular`]: no mode moves its point along a tangent direction):
    /// always when a contact with fixed rows has a singular block, else when a closed one
    /// without fixed rows has. The solvers then take the local solves and residuals that
    /// handle it (THEORY §4.4); otherwise, the common case, the same code without their
    /// tests.
    #[inline(always)]
    pub fn may_be_singular(&self) -> bool {
        self.fixed_singular | self.moving_singular
    }

    #[inline(always)]
    fn compute_rows(
        &mut self,
        contact: usize,
        tangents: &[Vector3<f64>; 2],
        rows: &[f64],
        apply_a_inv: impl Fn(&[f64], &mut [f64]),
    ) {
        let p = self.p;
        let [x, y, z] = thirds(rows, p);
        for (a, t) in tangents.iter().enumerate() {
            let r = 2 * contact + a;
            let l = &mut self.l[r * p..(r + 1) * p];
            map3(l, x, y, z, |x, y, z| t.x * x + t.y * y + t.z * z);
            apply_a_inv(l, &mut self.al[r * p..(r + 1) * p]);
        }
    }

    /// Removes every slot.
    #[inline]
    pub fn clear(&mut self) {
        self.slots.clear();
        self.block_of.clear();
        self.all_fixed = true;
        self.moving_singular = false;
    }

    /// Number of closed contacts `m` (the problem has `2m` unknowns).
    #[inline]
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// True when no contact is closed.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// The closed contacts.
    #[inline]
    pub fn slots(&self) -> &[Slot] {
        &self.slots
    }

    /// Adds a closed contact with its tangent basis, point rows (3 × p), and the diagonal of
    /// `A⁻¹` (modal coordinates); see [`push_with`](Self::push_with).
    #[inline]
    pub fn push(&mut self, slot: Slot, tangents: &[Vector3<f64>; 2], rows: &[f64], a_inv: &[f64]) {
        self.push_with(slot, tangents, rows, |l, out| {
            for i in 0..l.len() {
                out[i] = a_inv[i] * l[i];
            }
        });
    }

    /// Adds a closed contact with its tangent basis and point rows (3 × p); `apply_a_inv(l, out)`
    /// computes `out = A⁻¹ l` (ignored for a contact whose rows were fixed). The contact's
    /// velocity terms enter `b` when [`assemble`](Self::assemble) is called.
    #[inline]
    pub fn push_with(
        &mut self,
        slot: Slot,
        tangents: &[Vector3<f64>; 2],
        rows: &[f64],
        apply_a_inv: impl Fn(&[f64], &mut [f64]),
    ) {
        let block = if self.fixed[slot.contact] {
            slot.contact
        } else {
            self.compute_rows(slot.contact, tangents, rows, apply_a_inv);
            self.all_fixed = false;
            self.fixed.len() + self.slots.len()
        };
        self.block_of.push(block);
        self.slots.push(slot);
    }

    /// Assembles `H` and `b = L q̈_free + (L q̇* − v_imp)/(θΔt)`. `v_imp(slot)` gives the
    /// obstacle's tangential velocity at a slot's contact, in its tangent basis.
    #[inline(always)]
    pub fn assemble(
        &mut self,
        qdd_free: &[f64],
        qd_star: &[f64],
        theta_dt: f64,
        v_imp: impl Fn(&Slot) -> Vector2<f64>,
    ) {
        self.assemble_with::<Portable>(qdd_free, qd_star, theta_dt, v_imp)
    }

    /// [`Self::assemble`] with the reduction kernels `K` ([`crate::numerics`]).
    #[inline(always)]
    pub(crate) fn assemble_with<K: Lanes>(
        &mut self,
        qdd_free: &[f64],
        qd_star: &[f64],
        theta_dt: f64,
        v_imp: impl Fn(&Slot) -> Vector2<f64>,
    ) {
        let p = self.p;
        let m = self.slots.len();
        let st = self.stride;
        let inverse_theta_dt = 1.0 / theta_dt;
        // H of fixed rows depends only on which contacts are closed: the one in `h` serves
        // while they stay the same (a contact stays closed for many steps)
        let all_fixed = self.all_fixed;
        let h_kept = all_fixed && same_contacts(&self.h_for, &self.slots);
        if !h_kept {
            self.h_for.clear();
            if all_fixed {
                self.h_for.extend(self.slots.iter().map(|s| s.contact));
            }
        }
        for k in 0..m {
            let ck = self.slots[k].contact;
            let fixed_k = self.fixed[ck];
            // the 2 × 2 blocks H_kl, l ≥ k, and their transposes (none when kept)
            let last = if h_kept { k } else { m };
            for l in k..last {
                let cl = self.slots[l].contact;
                if fixed_k && self.fixed[cl] {
                    // gathered whole: h_fixed is exactly symmetric (fix_rows)
                    for a in 0..2 {
                        let from = &self.h_fixed[(2 * ck + a) * st + 2 * cl..][..2];
                        let (x, y) = (from[0], from[1]);
                        let row = (2 * k + a) * st + 2 * l;
                        self.h[row] = x;
                        self.h[row + 1] = y;
                        if l != k {
                            self.h[2 * l * st + 2 * k + a] = x;
                            self.h[(2 * l + 1) * st + 2 * k + a] = y;
                        }
                    }
                    continue;
                }
                for a in 0..2 {
                    let (hr, lr) = (2 * k + a, 2 * ck + a);
                    for b in 0..2 {
                        if l == k && b < a {
                            continue; // the diagonal block's lower half, by symmetry
                        }
                        let (hc, lc) = (2 * l + b, 2 * cl + b);
                        let v = K::dot(
                            &self.l[lr * p..(lr + 1) * p],
                            &self.al[lc * p..(lc + 1) * p],
                        );
                        self.h[hr * st + hc] = v;
                        self.h[hc * st + hr] = v;
                    }
                }
            }
            let vimp = v_imp(&self.slots[k]);
            for a in 0..2 {
                let lr = &self.l[(2 * ck + a) * p..(2 * ck + a + 1) * p];
                let (acceleration, velocity) = K::dot2(lr, qdd_free, qd_star);
                self.b[2 * k + a] = acceleration + (velocity - vimp[a]) * inverse_theta_dt;
            }
            self.newton[k].set(f64::NAN);
            if !fixed_k {
                // a fixed contact's block was prepared once ([`Self::diagonal_block`])
                let block = DiagonalBlock::new(self.block(k, k));
                self.moving_singular |= block.is_singular();
                self.blocks[self.block_of[k]] = block;
            }
        }
    }

    /// Entry `H[r][c]` (scalar indices over the 2m unknowns).
    #[inline]
    pub fn h(&self, r: usize, c: usize) -> f64 {
        self.h[r * self.stride + c]
    }

    /// The 2 × 2 block `H_kl`.
    #[inline]
    pub fn block(&self, k: usize, l: usize) -> Matrix2<f64> {
        Matrix2::new(
            self.h(2 * k, 2 * l),
            self.h(2 * k, 2 * l + 1),
            self.h(2 * k + 1, 2 * l),
            self.h(2 * k + 1, 2 * l + 1),
        )
    }

    /// Slot `k`'s Newton start within the step ([`crate::contact::friction::local_solve_block`]).
    #[inline]
    pub(crate) fn newton_start(&self, k: usize) -> &Cell<f64> {
        &self.newton[k]
    }

    /// `H_kk` prepared for its local solve: prepared once for a fixed contact
    /// ([`Self::fix_rows`]), by [`Self::assemble`] for the others.
    #[inline]
    pub fn diagonal_block(&self, k: usize) -> &DiagonalBlock {
        &self.blocks[self.block_of[k]]
    }

    /// `b_k`.
    #[inline]
    pub fn rhs(&self, k: usize) -> Vector2<f64> {
        Vector2::new(self.b[2 * k], self.b[2 * k + 1])
    }

    /// `b_k − Σ_{l≠k} H_kl λ_l`: the right-hand side of contact k's local problem. In line
    /// wherever it is called (the sweeps, the Active Set's status tests: a call costs these
    /// short loops ~1 % of the Active Set's step).
    #[inline(always)]
    pub fn local_rhs(&self, k: usize, lambda: &[Vector2<f64>]) -> Vector2<f64> {
        let m = self.slots.len().min(lambda.len());
        let row0 = &self.h[2 * k * self.stride..][..2 * m];
        let row1 = &self.h[(2 * k + 1) * self.stride..][..2 * m];
        let (mut c0, mut c1) = (self.b[2 * k], self.b[2 * k + 1]);
        for (l, ((lam, h0), h1)) in lambda[..m]
            .iter()
            .zip(row0.chunks_exact(2))
            .zip(row1.chunks_exact(2))
            .enumerate()
        {
            if l != k {
                c0 -= h0[0] * lam.x + h0[1] * lam.y;
                c1 -= h1[0] * lam.x + h1[1] * lam.y;
            }
        }
        Vector2::new(c0, c1)
    }

    /// `(b − Hλ)_k`: contact k's tangential velocity relative to the obstacle, divided by θΔt
    /// (`H_kk` read from its prepared block: the numbers of [`Self::block`]`(k, k)`, one load).
    #[inline]
    pub fn residual_velocity(&self, k: usize, lambda: &[Vector2<f64>]) -> Vector2<f64> {
        self.local_rhs(k, lambda) - self.diagonal_block(k).h * lambda[k]
    }

    /// `q̈ −= A⁻¹ Lᵀ λ`, row by row with the kernels `K` (`q̈ += (−λ_r) (A⁻¹Lᵀ)_r`: the
    /// same bits as `q̈ −= λ_r (A⁻¹Lᵀ)_r`).
    #[inline(always)]
    pub(crate) fn apply<K: Lanes>(&self, lambda: &[Vector2<f64>], qdd: &mut [f64]) {
        let p = self.p;
        for (slot, lam) in self.slots.iter().zip(lambda) {
            // the contact's two rows, side by side
            let rows = &self.al[2 * slot.contact * p..][..2 * p];
            for (al, s) in rows.chunks_exact(p.max(1)).zip([lam.x, lam.y]) {
                if s != 0.0 {
                    K::axpy(qdd, -s, al);
                }
            }
        }
    }
}

/// Whether `contacts` are the contacts of `slots`, in order (a cached `H` or answer still
/// holds).
#[inline]
pub(super) fn same_contacts(contacts: &[usize], slots: &[Slot]) -> bool {
    contacts.len() == slots.len() && contacts.iter().zip(slots).all(|(c, s)| *c == s.contact)
}

/// What the Delassus tests share.
#[cfg(test)]
pub(super) mod fixtures {
    use nalgebra::{Vector2, Vector3};

    use super::{Slot, TangentialProblem};

    /// Three contacts with fixed rows (p = 4) and a diagonal `A⁻¹`.
    pub(in crate::contact::delassus) fn fixed_problem() -> TangentialProblem {
        let (p, contacts) = (4, 3);
        let a_inv = [0.5, 1.5, 2.0, 0.25];
        let mut problem = TangentialProblem::new(p, contacts);
        let tangents = [Vector3::new(1.0, 0.0, 0.0), Vector3::new(0.0, 0.6, 0.8)];
        for c in 0..contacts {
            let rows: Vec<f64> = (0..3 * p)
                .map(|i| ((i * 5 + c * 11) % 7) as f64 - 2.5)
                .collect();
            problem.fix_rows(c, &tangents, &rows, |l, out| {
                for i in 0..l.len() {
                    out[i] = a_inv[i] * l[i];
                }
            });
        }
        problem
    }

    /// Closes `contacts` (thresholds 1 and 0.8) and assembles the problem.
    pub(in crate::contact::delassus) fn closed(
        problem: &mut TangentialProblem,
        contacts: &[usize],
    ) {
        problem.clear();
        for &c in contacts {
            let slot = Slot {
                contact: c,
                s_static: 1.0,
                s_dynamic: 0.8,
            };
            problem.push(slot, &[Vector3::zeros(); 2], &[], &[]);
        }
        problem.assemble(&[0.1, -0.2, 0.3, 0.4], &[1.0, 2.0, -1.0, 0.5], 1e-3, |_| {
            Vector2::zeros()
        });
    }
}

#[cfg(test)]
mod tests {
    use super::fixtures::{closed, fixed_problem};

    /// `H` kept from the last step while the same contacts are closed is the `H` a fresh
    /// problem gathers for them, bit for bit, whatever closed before.
    #[test]
    fn a_kept_delassus_matrix_is_the_one_gathered_again() {
        let mut problem = fixed_problem();
        for contacts in [
            &[0, 1][..],
            &[0, 1],
            &[1, 2],
            &[1, 2],
            &[0, 1, 2],
            &[0, 1, 2],
            &[2],
            &[0, 2],
            &[0, 2],
        ] {
            closed(&mut problem, contacts);
            let mut fresh = fixed_problem();
            closed(&mut fresh, contacts);
            let n = 2 * contacts.len();
            for r in 0..n {
                for c in 0..n {
                    assert_eq!(
                        problem.h(r, c).to_bits(),
                        fresh.h(r, c).to_bits(),
                        "{contacts:?}: H[{r}][{c}]"
                    );
                }
                assert_eq!(problem.b[r].to_bits(), fresh.b[r].to_bits());
            }
        }
    }
}
