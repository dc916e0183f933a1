//! Output samples, preallocated (for the whole run, or for a chunk that a streaming driver
//! drains with [`Recorder::clear`]): writing a sample allocates nothing.

use ndarray::{Array1, Array2, Array3};

/// Time histories at the output samples (every `every`-th step, t = 0 included).
#[derive(Debug, Clone)]
pub struct Recorder {
    /// Sample times `t` (N), s.
    pub t: Array1<f64>,
    /// Modal displacements `q` (N, p).
    pub q: Array2<f64>,
    /// Modal velocities `q̇` (N, p), full step.
    pub qdot: Array2<f64>,
    /// Normal force magnitude `R_N ≥ 0` (N, c), N.
    pub normal_force: Array2<f64>,
    /// Tangential force of the obstacle on the structure in the contact's tangent basis (N, c, 2), N.
    pub tangential_force: Array3<f64>,
    /// Tangential velocity relative to the obstacle, full step, tangent basis (N, c, 2), m/s.
    pub slip_velocity: Array3<f64>,
    /// Penetration `δ` (N, c), m; negative values are the remaining clearance.
    pub penetration: Array2<f64>,
    /// 0 open, 1 stick, 2 slip (N, c).
    pub status: Array2<i8>,
    /// Position of the point relative to the obstacle (N, c, 2), m: for a hole, the offset
    /// of the tube axis from the hole's centre in the hole's axes `(e1, e2)` — its orbit; for
    /// a plane or bars, the distance from the plane (mid-plane) and the position along `t1`
    /// ([`crate::obstacle::Obstacle::local`]).
    pub position: Array3<f64>,
    len: usize,
}

/// One contact's values at a sample.
#[derive(Debug, Clone, Copy)]
pub struct ContactSample {
    pub normal_force: f64,
    pub tangential_force: [f64; 2],
    pub slip_velocity: [f64; 2],
    pub penetration: f64,
    pub status: i8,
    pub position: [f64; 2],
}

impl Recorder {
    /// Room for `samples` samples of `p` modes and `c` contacts.
    pub fn new(samples: usize, p: usize, c: usize) -> Self {
        Self {
            t: Array1::zeros(samples),
            q: Array2::zeros((samples, p)),
            qdot: Array2::zeros((samples, p)),
            normal_force: Array2::zeros((samples, c)),
            tangential_force: Array3::zeros((samples, c, 2)),
            slip_velocity: Array3::zeros((samples, c, 2)),
            penetration: Array2::zeros((samples, c)),
            status: Array2::zeros((samples, c)),
            position: Array3::zeros((samples, c, 2)),
            len: 0,
        }
    }

    /// Number of samples written.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Room for this many samples.
    pub fn capacity(&self) -> usize {
        self.t.len()
    }

    /// True when no other sample fits.
    pub fn is_full(&self) -> bool {
        self.len >= self.t.len()
    }

    /// Forgets the samples written (after they were saved), keeping the room.
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// True when nothing was written.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Writes the modal state of the next sample; contacts follow with [`contact`](Self::contact).
    /// Returns false when the recorder is full.
    #[inline]
    pub fn push_state(&mut self, t: f64, q: &[f64], qdot: &[f64]) -> bool {
        if self.len >= self.t.len() {
            return false;
        }
        let n = self.len;
        self.t[n] = t;
        for (dst, src) in self.q.row_mut(n).iter_mut().zip(q) {
            *dst = *src;
        }
        for (dst, src) in self.qdot.row_mut(n).iter_mut().zip(qdot) {
            *dst = *src;
        }
        self.len += 1;
        true
    }

    /// Writes contact `c` of the last sample.
    #[inline]
    pub fn contact(&mut self, c: usize, s: &ContactSample) {
        let n = self.len - 1;
        self.normal_force[[n, c]] = s.normal_force;
        self.tangential_force[[n, c, 0]] = s.tangential_force[0];
        self.tangential_force[[n, c, 1]] = s.tangential_force[1];
        self.slip_velocity[[n, c, 0]] = s.slip_velocity[0];
        self.slip_velocity[[n, c, 1]] = s.slip_velocity[1];
        self.penetration[[n, c]] = s.penetration;
        self.status[[n, c]] = s.status;
        self.position[[n, c, 0]] = s.position[0];
        self.position[[n, c, 1]] = s.position[1];
    }

    /// Forgets the last sample written (one that must not be kept).
    pub fn discard_last(&mut self) {
        self.len = self.len.saturating_sub(1);
    }

    /// Drops the unwritten tail (after an early stop), keeping the samples written.
    pub fn truncate(&mut self) {
        let n = self.len;
        self.t = self.t.slice(ndarray::s![..n]).to_owned();
        self.q = self.q.slice(ndarray::s![..n, ..]).to_owned();
        self.qdot = self.qdot.slice(ndarray::s![..n, ..]).to_owned();
        self.normal_force = self.normal_force.slice(ndarray::s![..n, ..]).to_owned();
        self.tangential_force = self
            .tangential_force
            .slice(ndarray::s![..n, .., ..])
            .to_owned();
        self.slip_velocity = self
            .slip_velocity
            .slice(ndarray::s![..n, .., ..])
            .to_owned();
        self.penetration = self.penetration.slice(ndarray::s![..n, ..]).to_owned();
        self.status = self.status.slice(ndarray::s![..n, ..]).to_owned();
        self.position = self.position.slice(ndarray::s![..n, .., ..]).to_owned();
    }
}
