//! The tangential problem of the Lagrange methods: the Delassus operator `H = L A⁻¹ Lᵀ` over the
//! closed contacts, the right-hand side `b`, and the friction disks (THEORY §2, §4.2).
//!
//! `L` stacks, for each closed contact `k`, the two rows `t_aᵀ Φ_c` (a = 1, 2). With the stick
//! constraint acting on the velocity `L q̇* + θ Δt L q̈` (θ = 1: half-step velocity, the default;
//! θ = ½: the paper's literal full-step velocity),
//!
//! ```text
//!     γ_imp = (v_imp − L q̇*)/(θ Δt),     b = L q̈_free − γ_imp,     H λ = b  (stick)
//! ```
//!
//! and whatever λ is, the tangential velocity the constraint sees is `v_imp + θ Δt (b − H λ)`.
//! All buffers are sized once for every contact being closed: assembling allocates nothing.
//! The rows of a contact whose tangent basis never changes (a fixed plane) are computed once,
//! and so are the blocks of `H` between two such contacts: a step then only gathers them.

use std::cell::Cell;

use nalgebra::{Matrix2, Vector2, Vector3};

use crate::contact::friction::{DiagonalBlock, Slide};
use crate::kernels::{Lanes, Portable, map3};
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
    p: usize,
    slots: Vec<Slot>,
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
    b: Vec<f64>,
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
    sweep: Vec<Cell<[Vector2<f64>; 2]>>,
    stride: usize,
    /// The closed contacts of the last singularity test whose `H` was made of fixed rows
    /// only, and its answer ([`Self::is_singular`]).
    singular_for: Vec<usize>,
    singular: Option<bool>,
    /// The closed contacts whose `H`, made of fixed rows only, is in `h` (empty: none):
    /// [`Self::assemble`] gathers it again only when they change.
    h_for: Vec<usize>,
    /// Whether every slot's rows are fixed (kept by [`Self::clear`] and [`Self::push_with`]).
    all_fixed: bool,
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

    /// [`Self::assemble`] with the reduction kernels `K` ([`crate::kernels`]).
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

    /// Natural-map residual of the tangential problem (THEORY §4.2), the same measure for
    /// every solver: per contact `r_i = λ_i − proj_{disk(s_i)}(λ_i + ρ_i w_i)` with
    /// `w = b − Hλ` (the slip velocity over θΔt, along which a sliding λ points),
    /// `ρ_i = 2/tr(H_ii)` and `s_i` the static threshold of a sticking contact, the dynamic one
    /// of a sliding contact; it is 0 exactly when λ satisfies Coulomb's law. Returned as
    /// `‖r‖ / max(‖λ‖, max_i s_i)`, relative to the friction forces at stake.
    pub fn natural_map_residual(&self, lambda: &[Vector2<f64>], slide: &[Slide]) -> f64 {
        self.natural_map_residual_given(lambda, slide, |_| None)
    }

    /// [`Self::natural_map_residual`] of a single contact whose local right-hand side
    /// (`b`, or the one its last sweep recorded) is `c` (`SINGULAR`: [`slot_residual`]).
    #[inline(always)]
    fn single_residual<const SINGULAR: bool>(
        &self,
        lambda: Vector2<f64>,
        c: Vector2<f64>,
        slide: Slide,
    ) -> f64 {
        let block = self.diagonal_block(0);
        let slot = &self.slots[0];
        let (r2, l2) =
            slot_residual::<SINGULAR>(lambda, c - block.h * lambda, block.rho(), slot, slide);
        relative_residual(0.0 + r2, 0.0 + l2, 0.0f64.max(slot.s_static))
    }

    /// [`Self::natural_map_residual_after_sweep`] of a single closed contact whose sweep
    /// found `lambda` with status `slide`, its block regular ([`Self::may_be_singular`]
    /// false): the same operations, inlined into the caller (the common case of a rattling
    /// structure, at every step with a closed contact).
    #[inline(always)]
    pub fn single_residual_after_sweep(&self, lambda: Vector2<f64>, slide: Slide) -> f64 {
        let [c, _] = self.sweep[0].get();
        self.single_residual::<false>(lambda, c, slide)
    }

    /// Records slot `k`'s local solve in a Gauss–Seidel sweep: its right-hand side `c_k`
    /// (the other contacts' λ as they were then) and the change of its `λ_k`.
    #[inline]
    pub(crate) fn record_sweep(&self, k: usize, rhs: Vector2<f64>, change: Vector2<f64>) {
        self.sweep[k].set([rhs, change]);
    }

    /// [`Self::natural_map_residual`] at the end of a Gauss–Seidel sweep whose every local
    /// solve was recorded ([`Self::record_sweep`]), without forming `Hλ` again: slot `k`'s
    /// right-hand side saw the new λ of the slots before it and the old λ of those after it,
    /// so `w_k = c_k − H_kk λ_k − Σ_{j>k} H_kj Δλ_j` (exactly `w_k` of
    /// [`Self::residual_velocity`] up to the order of the sums; for a single contact, the
    /// same operations).
    pub fn natural_map_residual_after_sweep(
        &self,
        lambda: &[Vector2<f64>],
        slide: &[Slide],
    ) -> f64 {
        self.natural_map_residual_after_sweep_with::<true>(lambda, slide)
    }

    /// [`Self::natural_map_residual_after_sweep`]; `!SINGULAR` when no block is singular
    /// ([`Self::may_be_singular`], [`slot_residual`]).
    #[inline(always)]
    pub(crate) fn natural_map_residual_after_sweep_with<const SINGULAR: bool>(
        &self,
        lambda: &[Vector2<f64>],
        slide: &[Slide],
    ) -> f64 {
        let m = self.slots.len().min(lambda.len());
        if m == 1 {
            // a single contact (the common case), without the loops: the same operations
            let [c, _] = self.sweep[0].get();
            return self.single_residual::<SINGULAR>(lambda[0], c, slide[0]);
        }
        self.natural_map::<SINGULAR>(lambda, slide, |k| {
            let [c, _] = self.sweep[k].get();
            let mut w = c - self.diagonal_block(k).h * lambda[k];
            for j in k + 1..m {
                w -= self.block(k, j) * self.sweep[j].get()[1];
            }
            w
        })
    }

    /// [`Self::natural_map_residual`] with contact `k`'s local right-hand side
    /// `c_k = b_k − Σ_{l≠k} H_kl λ_l` given by `rhs(k)` where it is known (`Some`): a solver
    /// that formed it from the final λ passes it rather than have it formed again; the same
    /// operations, so the same bits.
    pub fn natural_map_residual_given(
        &self,
        lambda: &[Vector2<f64>],
        slide: &[Slide],
        rhs: impl Fn(usize) -> Option<Vector2<f64>>,
    ) -> f64 {
        self.natural_map_residual_given_with::<true>(lambda, slide, rhs)
    }

    /// [`Self::natural_map_residual_given`]; `!SINGULAR` when no block is singular
    /// ([`Self::may_be_singular`], [`slot_residual`]).
    #[inline(always)]
    pub(crate) fn natural_map_residual_given_with<const SINGULAR: bool>(
        &self,
        lambda: &[Vector2<f64>],
        slide: &[Slide],
        rhs: impl Fn(usize) -> Option<Vector2<f64>>,
    ) -> f64 {
        if self.slots.len() == 1 && !lambda.is_empty() {
            // a single contact (the common case), without the loops: the same operations
            return self.single_residual::<SINGULAR>(lambda[0], self.rhs(0), slide[0]);
        }
        self.natural_map::<SINGULAR>(lambda, slide, |k| match rhs(k) {
            Some(c) => c - self.diagonal_block(k).h * lambda[k],
            None => self.residual_velocity(k, lambda),
        })
    }

    /// The natural-map residual with the residual velocities `w(k) = (b − Hλ)_k`.
    #[inline]
    fn natural_map<const SINGULAR: bool>(
        &self,
        lambda: &[Vector2<f64>],
        slide: &[Slide],
        w: impl Fn(usize) -> Vector2<f64>,
    ) -> f64 {
        let mut r2 = 0.0;
        let mut l2 = 0.0;
        let mut s_max = 0.0f64;
        for (k, slot) in self.slots.iter().enumerate() {
            let (r, l) = slot_residual::<SINGULAR>(
                lambda[k],
                w(k),
                self.diagonal_block(k).rho(),
                slot,
                slide[k],
            );
            r2 += r;
            l2 += l;
            s_max = s_max.max(slot.s_static);
        }
        relative_residual(r2, l2, s_max)
    }

    /// `q̈ −= A⁻¹ Lᵀ λ`, row by row with the kernels `K` (`q̈ += (−λ_r) (A⁻¹Lᵀ)_r`: the
    /// same bits as `q̈ −= λ_r (A⁻¹Lᵀ)_r`).
    #[inline(always)]
    pub(crate) fn apply<K: crate::kernels::Lanes>(&self, lambda: &[Vector2<f64>], qdd: &mut [f64]) {
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

    /// Whether `H` is singular (redundant constraints, THEORY §4.6): a pivot of its `LDLᵀ`
    /// factorisation (the Cholesky's, before its square root) below `1e-12` of the largest
    /// diagonal term. `work` must hold `(2m)² + 4m` values.
    ///
    /// When every closed contact's rows are fixed (planes, bars), `H` depends only on which
    /// contacts are closed: the factorisation is then redone only when that set changes
    /// (at an impact or a release), and the last answer is given otherwise. More than `p`
    /// rows (2m > p) make `H` singular by its rank: no factorisation then (THEORY §4.6).
    #[inline(always)]
    pub fn is_singular(&mut self, work: &mut [f64]) -> bool {
        if self.slots.is_empty() {
            return false;
        }
        // the last answer (in line: the common case of a step)
        match self.singular {
            Some(singular) if self.all_fixed && same_contacts(&self.singular_for, &self.slots) => {
                singular
            }
            _ => self.test_singular(work),
        }
    }

    /// [`Self::is_singular`] when its last answer does not serve: the test, kept for the
    /// closed contacts when their rows are fixed.
    #[inline(never)]
    fn test_singular(&mut self, work: &mut [f64]) -> bool {
        let n = 2 * self.slots.len();
        let all_fixed = self.all_fixed;
        // H = L A⁻¹ Lᵀ has rank at most p: more than p rows of L are dependent, and the
        // factorisation would only confirm it
        let singular = n > self.p || self.factor_singular(work, n);
        self.singular = all_fixed.then_some(singular);
        self.singular_for.clear();
        self.singular_for
            .extend(self.slots.iter().map(|s| s.contact));
        singular
    }

    /// The pivot test of [`Self::is_singular`] on the current `H`: its lower triangle into
    /// `work`, then [`ldlt_singular`] with `tiny = 1e-12 max|H_ii|` (a 2 × 2 `H` in line).
    fn factor_singular(&self, work: &mut [f64], n: usize) -> bool {
        if n == 2 {
            // a single contact, the common case: its lower triangle on the stack
            let (a00, a10, a11) = (self.h(0, 0), self.h(1, 0), self.h(1, 1));
            let tiny = 1e-12 * a00.abs().max(a11.abs()).max(f64::MIN_POSITIVE);
            return ldlt_singular(&mut [a00, 0.0, a10, a11], &mut [0.0; 2], 2, tiny);
        }
        let (a, rest) = work.split_at_mut(n * n);
        let mut dmax = 0.0f64;
        for i in 0..n {
            for j in 0..=i {
                a[i * n + j] = self.h(i, j);
            }
            dmax = dmax.max(a[i * n + i].abs());
        }
        ldlt_singular(a, &mut rest[..n], n, 1e-12 * dmax.max(f64::MIN_POSITIVE))
    }

    /// Solves `H_SS λ_S = b_S − H_SF λ_F` for the stick slots `S` (those with `stick[k]`),
    /// the others' λ fixed, by Cholesky on the `2|S|` unknowns. `work` must hold
    /// `(2m)² + 4m` values and `index` 2m. Returns true when `H_SS` was singular (a pivot below `1e-12`
    /// of the largest diagonal term), in which case a Tikhonov term of that size regularises
    /// it (THEORY §4.6): when `b_S − H_SF λ_F` has a component `x_d` along a null direction
    /// of `H_SS` (no λ makes those contacts stick), the regularised `λ_S` has one of
    /// `x_d/(10^k τ)` along it, beyond the static disks unless `|x_d|` is of the order of
    /// `τ s`, and the Active Set's stick test refuses it. A single stick slot is solved by
    /// its block's inverse, regularised as in the local solves ([`DiagonalBlock`],
    /// THEORY §4.3, §4.4); a slot whose block is zero is coupled with no other and is solved
    /// alone ([`DiagonalBlock::stick_force`]).
    pub fn solve_stick(
        &self,
        stick: &[bool],
        lambda: &mut [Vector2<f64>],
        work: &mut [f64],
        index: &mut [usize],
    ) -> bool {
        let m = self.slots.len();
        let mut n = 0;
        for k in 0..m {
            if stick[k] {
                index[n] = 2 * k;
                index[n + 1] = 2 * k + 1;
                n += 2;
            }
        }
        if n == 0 {
            return false;
        }
        if n == 2 {
            // one stick contact (a structure that sticks, mostly): its unknowns are its
            // local problem's free solution `H_kk⁻¹ c_k`, the inverse formed once per step
            // (regularised when singular, as in the local solves: THEORY §4.4)
            let k = index[0] / 2;
            let block = self.diagonal_block(k);
            if block.is_singular() {
                return self.single_singular_stick(k, lambda);
            }
            lambda[k] = block.inverse() * self.local_rhs(k, lambda);
            return false;
        }
        let mut singular = false;
        if self.may_be_singular() && self.blocks_zero(stick) {
            // a zero block's λ is its own (no mode moves its point: it is coupled with no
            // other contact), and its H_kk = 0 would leave the factorisation no scale
            n = self.drop_zero_blocks(stick, lambda, index);
            singular = true;
            if n == 0 {
                return true;
            }
        }
        let (a, rest) = work.split_at_mut(n * n);
        let (x, rest) = rest.split_at_mut(n);
        let diag = &mut rest[..n];
        let mut dmax = 0.0f64;
        for i in 0..n {
            let ri = index[i];
            for j in 0..n {
                a[i * n + j] = self.h(ri, index[j]);
            }
            diag[i] = a[i * n + i];
            dmax = dmax.max(diag[i].abs());
            // rhs: b_i − Σ_{free slots} H λ
            let mut v = self.b[ri];
            for (l, lam) in lambda.iter().enumerate().take(m) {
                if !stick[l] {
                    v -= self.h(ri, 2 * l) * lam.x + self.h(ri, 2 * l + 1) * lam.y;
                }
            }
            x[i] = v;
        }
        singular |= cholesky_solve(a, diag, x, n, 1e-12 * dmax.max(f64::MIN_POSITIVE));
        for i in (0..n).step_by(2) {
            lambda[index[i] / 2] = Vector2::new(x[i], x[i + 1]);
        }
        singular
    }

    /// [`Self::solve_stick`] of the single stick slot `k` whose block is singular: its
    /// block's stick force ([`DiagonalBlock::stick_force`], as in its local solves). Returns
    /// true (singular).
    #[cold]
    #[inline(never)]
    fn single_singular_stick(&self, k: usize, lambda: &mut [Vector2<f64>]) -> bool {
        let c = self.local_rhs(k, lambda);
        lambda[k] = self
            .diagonal_block(k)
            .stick_force(&c, self.slots[k].s_static);
        true
    }

    /// Whether a stick slot's diagonal block is zero ([`DiagonalBlock::is_zero`]).
    #[inline]
    fn blocks_zero(&self, stick: &[bool]) -> bool {
        (0..self.slots.len()).any(|k| stick[k] && self.diagonal_block(k).is_zero())
    }

    /// [`Self::solve_stick`] when a stick slot's block is zero: such a slot's `L_k` rows are
    /// zero (`H_kk = L_k A⁻¹ L_kᵀ`, `A⁻¹` positive), so it is coupled with no other slot and
    /// its `λ_k` is its block's stick force ([`DiagonalBlock::stick_force`]: 0 when its
    /// right-hand side is, else one the stick test refuses). Writes those, and the unknowns
    /// of the other stick slots into `index`; returns their number.
    #[cold]
    #[inline(never)]
    fn drop_zero_blocks(
        &self,
        stick: &[bool],
        lambda: &mut [Vector2<f64>],
        index: &mut [usize],
    ) -> usize {
        let mut n = 0;
        for k in 0..self.slots.len() {
            if !stick[k] {
                continue;
            }
            let block = self.diagonal_block(k);
            if block.is_zero() {
                let c = self.local_rhs(k, lambda);
                lambda[k] = block.stick_force(&c, self.slots[k].s_static);
            } else {
                index[n] = 2 * k;
                index[n + 1] = 2 * k + 1;
                n += 2;
            }
        }
        n
    }
}

/// Whether the symmetric `n × n` matrix whose lower triangle (diagonal included) is in `a`
/// has a pivot of its `LDLᵀ` factorisation at most `tiny` (or not a number): the Cholesky's
/// pivot test (its pivots before their square roots, `d_j = a_jj − Σ_k l_jk² d_k`) with no
/// square root, one division per column and no solve — what a singularity test needs
/// (THEORY §4.6). `a` is overwritten; `inverse_pivots` holds `n` values.
#[inline(always)]
fn ldlt_singular(a: &mut [f64], inverse_pivots: &mut [f64], n: usize, tiny: f64) -> bool {
    for j in 0..n {
        let (done, row) = a.split_at_mut(j * n);
        let row = &mut row[..j + 1];
        // u_jk = l_jk d_k = a_jk − Σ_{i<k} u_ji l_ki, row k (< j) holding l_k·
        for k in 0..j {
            let lk = &done[k * n..k * n + k];
            let mut u = row[k];
            for (ui, li) in row[..k].iter().zip(lk) {
                u -= ui * li;
            }
            row[k] = u;
        }
        // d_j = a_jj − Σ_k u_jk l_jk, and row j turned into l_j·
        let mut d = row[j];
        for k in 0..j {
            let l = row[k] * inverse_pivots[k];
            d -= row[k] * l;
            row[k] = l;
        }
        if !(d > tiny) {
            return true;
        }
        inverse_pivots[j] = 1.0 / d;
    }
    false
}

/// In-place Cholesky solve of the SPD `n × n` system `a x = rhs` (rhs overwritten by x).
/// Only the upper triangle of `a` is read; `diag` must hold its diagonal. A pivot below `tiny`
/// marks the matrix singular: the factorisation is restarted on `a + shift·I` with the
/// smallest `shift = tiny·10^k` that succeeds; when none does (a non-finite `a`), `x` is NaN.
/// Returns whether regularisation was needed.
fn cholesky_solve(a: &mut [f64], diag: &[f64], x: &mut [f64], n: usize, tiny: f64) -> bool {
    // Factor into the lower triangle (diagonal included); the strict upper part keeps `a`.
    let factor = |a: &mut [f64], shift: f64| -> bool {
        for j in 0..n {
            for i in j + 1..n {
                a[i * n + j] = a[j * n + i];
            }
            a[j * n + j] = diag[j] + shift;
        }
        for j in 0..n {
            let mut d = a[j * n + j];
            for k in 0..j {
                d -= a[j * n + k] * a[j * n + k];
            }
            if !(d > tiny) {
                return false;
            }
            let d = d.sqrt();
            a[j * n + j] = d;
            for i in j + 1..n {
                let mut s = a[i * n + j];
                for k in 0..j {
                    s -= a[i * n + k] * a[j * n + k];
                }
                a[i * n + j] = s / d;
            }
        }
        true
    };
    let mut regularised = false;
    if !factor(a, 0.0) {
        regularised = true;
        let mut shift = tiny.max(1e-300);
        while !factor(a, shift) {
            shift *= 10.0;
            if !shift.is_finite() {
                // a non-finite H (a diverging run): no shift helps. NaN multipliers make the
                // step non-finite, and the run stops there as diverged (never a hang).
                x[..n].fill(f64::NAN);
                return true;
            }
        }
    }
    for i in 0..n {
        let mut s = x[i];
        for k in 0..i {
            s -= a[i * n + k] * x[k];
        }
        x[i] = s / a[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = x[i];
        for k in i + 1..n {
            s -= a[k * n + i] * x[k];
        }
        x[i] = s / a[i * n + i];
    }
    regularised
}

/// Whether `contacts` are the contacts of `slots`, in order (a cached `H` or answer still
/// holds).
#[inline]
fn same_contacts(contacts: &[usize], slots: &[Slot]) -> bool {
    contacts.len() == slots.len() && contacts.iter().zip(slots).all(|(c, s)| *c == s.contact)
}

/// One slot's terms of the natural-map residual ([`TangentialProblem::natural_map_residual`]):
/// `(|λ − proj_{disk(s)}(λ + ρ w)|², |λ|²)` for its `λ`, residual velocity `w`, `ρ` and status.
/// `SINGULAR`: a zero block's `ρ = ∞` is taken as its limit ([`zero_block_residual`]);
/// without it (no block singular, [`TangentialProblem::may_be_singular`]) `ρ` is finite.
#[inline(always)]
fn slot_residual<const SINGULAR: bool>(
    lambda: Vector2<f64>,
    w: Vector2<f64>,
    rho: f64,
    slot: &Slot,
    slide: Slide,
) -> (f64, f64) {
    let s = match slide {
        Slide::Stick => slot.s_static,
        Slide::Slip => slot.s_dynamic,
    };
    if SINGULAR && !(rho < f64::INFINITY) {
        return zero_block_residual(lambda, w, s);
    }
    let z = lambda + w * rho;
    let n2 = z.norm_squared();
    let projected = if n2 > s * s { z * (s / n2.sqrt()) } else { z };
    ((lambda - projected).norm_squared(), lambda.norm_squared())
}

/// [`slot_residual`] of a zero block (`ρ = ∞`, [`DiagonalBlock::rho`]): the natural map's
/// limit `proj_{disk(s)}(λ + ρ w) → s w/|w|` when `w ≠ 0`, `proj(λ)` when `w = 0` — the
/// residual is 0 exactly for Coulomb's solutions, `λ = s w/|w|` or `w = 0`, `|λ| ≤ s`.
#[cold]
#[inline(never)]
fn zero_block_residual(lambda: Vector2<f64>, w: Vector2<f64>, s: f64) -> (f64, f64) {
    let nw = w.norm();
    let projected = if nw > 0.0 {
        w * (s / nw)
    } else {
        let nl = lambda.norm();
        if nl > s { lambda * (s / nl) } else { lambda }
    };
    ((lambda - projected).norm_squared(), lambda.norm_squared())
}

/// `‖r‖ / max(‖λ‖, max_i s_i)` from the sums of squares (0 when both are 0).
#[inline(always)]
fn relative_residual(r2: f64, l2: f64, s_max: f64) -> f64 {
    let scale = l2.sqrt().max(s_max);
    if scale > 0.0 { r2.sqrt() / scale } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three contacts with fixed rows (p = 4) and a diagonal `A⁻¹`.
    fn fixed_problem() -> TangentialProblem {
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

    /// A single contact's singularity test, in line, answers as the general `LDLᵀ` path on its
    /// 2 × 2 `H`: regular, rank 1 (the two tangent rows equal), and the tangent rows
    /// 1e-5 and 1e-7 apart (second pivots ~2e-11 and ~2e-15 of the first, against 1e-12).
    #[test]
    fn a_single_contact_singularity_test_answers_as_the_general_one() {
        let p = 3;
        let a_inv = [0.5, 1.5, 2.0];
        for (gap, expected) in [(1.0, false), (0.0, true), (1e-5, false), (1e-7, true)] {
            let mut problem = TangentialProblem::new(p, 1);
            // the point's rows (3 × p): its x and y rows differ by `gap` in one entry, and
            // the tangents x and y make them the two rows of L
            let rows = [1.0, 2.0, -1.0, 1.0, 2.0 + gap, -1.0, 0.3, 0.1, 0.7];
            let tangents = [Vector3::new(1.0, 0.0, 0.0), Vector3::new(0.0, 1.0, 0.0)];
            let slot = Slot {
                contact: 0,
                s_static: 1.0,
                s_dynamic: 0.8,
            };
            problem.push(slot, &tangents, &rows, &a_inv);
            problem.assemble(&[0.0; 3], &[0.0; 3], 1e-3, |_| Vector2::zeros());
            let mut work = vec![0.0; 16];
            let inline = problem.is_singular(&mut work);
            let mut a = [problem.h(0, 0), 0.0, problem.h(1, 0), problem.h(1, 1)];
            let tiny = 1e-12 * problem.h(0, 0).abs().max(problem.h(1, 1).abs());
            assert_eq!(
                inline,
                ldlt_singular(&mut a, &mut [0.0; 2], 2, tiny),
                "gap {gap}"
            );
            assert_eq!(inline, expected, "gap {gap}");
        }
    }

    fn closed(problem: &mut TangentialProblem, contacts: &[usize]) {
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

    /// A single stick contact is solved by its block's inverse: the stick condition
    /// `(b − Hλ)_k = 0` holds to round-off, as the Cholesky of the general path makes it;
    /// with two stick contacts (the general path) the same holds for both.
    #[test]
    fn a_single_stick_contact_has_zero_slip_velocity() {
        let mut problem = fixed_problem();
        closed(&mut problem, &[0, 1, 2]);
        let (mut work, mut index) = (vec![0.0; 36 + 12], vec![0; 6]);
        for stick in [
            [true, false, false],
            [false, true, false],
            [false, false, true],
            [true, false, true],
        ] {
            let mut lambda = [
                Vector2::new(0.3, -0.1),
                Vector2::new(-0.2, 0.25),
                Vector2::new(0.05, 0.4),
            ];
            let frozen = lambda;
            assert!(!problem.solve_stick(&stick, &mut lambda, &mut work, &mut index));
            for k in 0..3 {
                if stick[k] {
                    let w = problem.residual_velocity(k, &lambda);
                    let scale =
                        problem.rhs(k).norm() + problem.block(k, k).norm() * lambda[k].norm();
                    assert!(w.norm() <= 1e-14 * scale, "{stick:?}: w_{k} = {w}");
                } else {
                    assert_eq!(lambda[k], frozen[k], "a sliding contact's λ is not touched");
                }
            }
        }
    }

    /// A stick contact whose block is singular (its two tangent rows equal): its stick force
    /// is the local solve's — the minimum-norm one when its right-hand side has no component
    /// along the null direction `d = (1, −1)/√2`, where it sticks exactly — and the solve says
    /// that the block was singular. With a component along `d` (the tangents' obstacle
    /// velocities differ: no λ makes it stick), the force is beyond the static disk, and the
    /// Active Set's stick test refuses it.
    #[test]
    fn a_singular_single_stick_block_is_solved_as_the_local_problem() {
        let (p, contacts) = (4, 1);
        let mut problem = TangentialProblem::new(p, contacts);
        let t = Vector3::new(0.0, 0.6, 0.8);
        let rows: Vec<f64> = (0..3 * p).map(|i| ((i * 5) % 7) as f64 - 2.5).collect();
        problem.fix_rows(0, &[t, t], &rows, |l, out| out.copy_from_slice(l));
        let (mut work, mut index) = (vec![0.0; 8], vec![0; 2]);
        for (vimp, sticks) in [(Vector2::zeros(), true), (Vector2::new(1e-3, 0.0), false)] {
            problem.clear();
            let slot = Slot {
                contact: 0,
                s_static: 1e3,
                s_dynamic: 0.8e3,
            };
            problem.push(slot, &[Vector3::zeros(); 2], &[], &[]);
            problem.assemble(&[0.1, -0.2, 0.3, 0.4], &[1.0, 2.0, -1.0, 0.5], 1e-3, |_| {
                vimp
            });
            assert!(problem.diagonal_block(0).is_singular());
            let mut lambda = [Vector2::zeros()];
            assert!(problem.solve_stick(&[true], &mut lambda, &mut work, &mut index));
            let l = lambda[0];
            let (local, slide) = crate::contact::friction::local_solve(
                &problem.block(0, 0),
                &problem.rhs(0),
                1e3,
                0.8e3,
                crate::contact::friction::LocalSolve::Exact,
            );
            if sticks {
                assert_eq!(slide, Slide::Stick);
                assert_eq!(l, local);
                // the minimum norm: nothing along d, and no slip velocity
                assert!((l.x - l.y).abs() <= 1e-12 * l.norm(), "{l}");
                let w = problem.residual_velocity(0, &lambda);
                assert!(w.norm() <= 1e-12 * problem.rhs(0).norm(), "w = {w}");
            } else {
                assert_eq!(slide, Slide::Slip);
                assert!(l.norm() > 1e3, "λ = {l} would pass the stick test");
            }
        }
    }

    /// Two stick contacts with the same rows (two obstacles on one point): `H_SS` is singular
    /// along `(d, −d)`. With the same obstacle velocities the right-hand side is consistent
    /// and the regularised solve sticks both with nearly the minimum-norm forces (equal
    /// halves to 1e-3, no slip velocity to 1e-9 of `b`); with different ones no λ sticks both,
    /// and the solve
    /// returns forces far beyond the static disks, which the Active Set's stick test refuses.
    #[test]
    fn a_singular_stick_system_with_an_inconsistent_right_hand_side_does_not_stick() {
        let (p, contacts) = (4, 2);
        let a_inv = [0.5, 1.5, 2.0, 0.25];
        let mut problem = TangentialProblem::new(p, contacts);
        let tangents = [Vector3::new(1.0, 0.0, 0.0), Vector3::new(0.0, 0.6, 0.8)];
        let rows: Vec<f64> = (0..3 * p).map(|i| ((i * 5) % 7) as f64 - 2.5).collect();
        for c in 0..contacts {
            problem.fix_rows(c, &tangents, &rows, |l, out| {
                for i in 0..l.len() {
                    out[i] = a_inv[i] * l[i];
                }
            });
        }
        let s = 1e3;
        let (mut work, mut index) = (vec![0.0; 16 + 8], vec![0; 4]);
        for (other, sticks) in [(Vector2::zeros(), true), (Vector2::new(1e-3, 0.0), false)] {
            problem.clear();
            for c in 0..contacts {
                let slot = Slot {
                    contact: c,
                    s_static: s,
                    s_dynamic: 0.8 * s,
                };
                problem.push(slot, &[Vector3::zeros(); 2], &[], &[]);
            }
            problem.assemble(
                &[0.1, -0.2, 0.3, 0.4],
                &[1.0, 2.0, -1.0, 0.5],
                1e-3,
                |slot| {
                    if slot.contact == 0 {
                        Vector2::zeros()
                    } else {
                        other
                    }
                },
            );
            let mut lambda = [Vector2::zeros(); 2];
            assert!(problem.solve_stick(&[true, true], &mut lambda, &mut work, &mut index));
            let largest = lambda[0].norm().max(lambda[1].norm());
            if sticks {
                // along (d, −d) the right-hand side is round-off, a few ε|b|, over the
                // shift ~1e-11 |H|: equal halves to 1e-3
                assert!(
                    (lambda[0] - lambda[1]).norm() <= 1e-3 * largest,
                    "{lambda:?}"
                );
                assert!(largest <= s, "{lambda:?}");
                for k in 0..2 {
                    let w = problem.residual_velocity(k, &lambda);
                    assert!(w.norm() <= 1e-9 * problem.rhs(k).norm(), "w_{k} = {w}");
                }
            } else {
                assert!(largest > 1e3 * s, "{lambda:?} would pass the stick test");
            }
        }
    }

    /// The square-root-free pivot test gives the Cholesky's answer: regular for SPD matrices
    /// (down to a smallest eigenvalue 1e-9 of the largest, at scales 1e-6 to 1e6), singular for a
    /// rank-deficient one (two contacts with the same rows), a pivot just below the
    /// threshold, and a NaN.
    #[test]
    fn ldlt_pivots_flag_what_the_cholesky_flags() {
        let test = |spd: &nalgebra::DMatrix<f64>| {
            let n = spd.nrows();
            let dmax = (0..n).map(|i| spd[(i, i)].abs()).fold(0.0, f64::max);
            let tiny = 1e-12 * dmax;
            let mut a: Vec<f64> = (0..n * n).map(|k| spd[(k / n, k % n)]).collect();
            let mut inverse_pivots = vec![0.0; n];
            let ldlt = ldlt_singular(&mut a, &mut inverse_pivots, n, tiny);
            let mut a: Vec<f64> = (0..n * n).map(|k| spd[(k / n, k % n)]).collect();
            let diag: Vec<f64> = (0..n).map(|i| spd[(i, i)]).collect();
            let cholesky = cholesky_solve(&mut a, &diag, &mut vec![0.0; n], n, tiny);
            assert_eq!(ldlt, cholesky, "{spd}");
            ldlt
        };
        for n in [2, 4, 6] {
            let m =
                nalgebra::DMatrix::<f64>::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 5) as f64 + 0.3);
            for smallest in [1.0f64, 1e-3, 1e-9] {
                // Q diag Qᵀ with eigenvalues from 1 down to `smallest`
                let q = m.clone().qr().q();
                let d =
                    nalgebra::DVector::from_fn(n, |i, _| smallest.powf(i as f64 / (n - 1) as f64));
                let spd = &q * nalgebra::DMatrix::from_diagonal(&d) * q.transpose();
                for scale in [1e-6, 1.0, 1e6] {
                    assert!(!test(&(&spd * scale)));
                }
            }
            // two contacts with the same rows: H = L Lᵀ with repeated rows of L
            let mut l =
                nalgebra::DMatrix::<f64>::from_fn(n, 8, |i, j| ((i * 5 + j * 11) % 7) as f64 - 3.0);
            for j in 0..8 {
                l[(n - 1, j)] = l[(0, j)];
            }
            assert!(test(&(&l * l.transpose())));
        }
        // the second pivot 1 − 0.99999999999999² ≈ 2e-14 below 1e-12: singular
        let near = nalgebra::DMatrix::from_row_slice(
            2,
            2,
            &[1.0, 0.99999999999999, 0.99999999999999, 1.0],
        );
        assert!(test(&near));
        let mut a = vec![1.0, 0.0, 0.0, f64::NAN];
        assert!(ldlt_singular(&mut a, &mut [0.0; 2], 2, 1e-12));
    }

    #[test]
    fn cholesky_of_a_non_finite_matrix_returns_nan_instead_of_looping() {
        // a NaN pivot fails every shifted factorisation: this looped forever
        let mut a = vec![1.0, 0.0, 0.0, f64::NAN];
        let mut x = vec![1.0, 1.0];
        assert!(cholesky_solve(&mut a, &[1.0, f64::NAN], &mut x, 2, 1e-12));
        assert!(x.iter().all(|v| v.is_nan()));
    }

    #[test]
    fn cholesky_matches_dense_solve_and_flags_singular() {
        let n = 4;
        let m = nalgebra::DMatrix::<f64>::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 5) as f64 + 0.3);
        let spd = &m * m.transpose() + nalgebra::DMatrix::identity(n, n);
        let rhs = nalgebra::DVector::from_fn(n, |i, _| i as f64 - 1.5);
        let mut a: Vec<f64> = (0..n * n).map(|k| spd[(k / n, k % n)]).collect();
        let diag: Vec<f64> = (0..n).map(|i| spd[(i, i)]).collect();
        let mut x: Vec<f64> = rhs.iter().copied().collect();
        assert!(!cholesky_solve(&mut a, &diag, &mut x, n, 1e-12));
        let exact = spd.clone().cholesky().unwrap().solve(&rhs);
        for i in 0..n {
            assert!((x[i] - exact[i]).abs() < 1e-12 * exact.amax());
        }
        // rank-deficient: two equal rows/columns
        let mut a = vec![1.0, 1.0, 1.0, 1.0];
        let mut x = vec![1.0, 1.0];
        assert!(cholesky_solve(&mut a, &[1.0, 1.0], &mut x, 2, 1e-12));
        assert!(x.iter().all(|v| v.is_finite()));
        // the regularised solution still solves the consistent system
        assert!((x[0] + x[1] - 1.0).abs() < 1e-6);
    }
}
