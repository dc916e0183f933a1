//! The stick system of the Active Set, `H_SS λ_S = b_S − H_SF λ_F` on the sticking contacts,
//! and the singularity test of `H` (redundant constraints), on the dense factorisations of
//! [`crate::numerics::dense`] (THEORY §4.3, §4.6).

use nalgebra::Vector2;

use super::problem::{TangentialProblem, same_contacts};
use crate::numerics::dense::{cholesky_solve, ldlt_singular};

impl TangentialProblem {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::delassus::Slot;
    use crate::contact::delassus::problem::fixtures::{closed, fixed_problem};
    use crate::contact::friction::Slide;
    use nalgebra::Vector3;

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
}
