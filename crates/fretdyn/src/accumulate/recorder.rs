//! Output samples, preallocated (for the whole run, or for a chunk that a streaming driver
//! drains with [`Recorder::clear`]): writing a sample allocates nothing.

use ndarray::{Array1, Array2, Array3};

use crate::error::{Error, Result};

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
    /// ([`crate::contact::obstacle::Obstacle::local`]).
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

    /// Bytes one output sample takes, in memory as in the streamed files: `t`, `q`, `q̇`
    /// (8 + 16 p), and per contact `R_N`, `R_T`, `v_T`, `δ`, position as `f64` and the status
    /// as `i8` (65 c). THEORY §5 lists the outputs.
    pub const fn bytes_per_sample(p: usize, c: usize) -> u64 {
        8 + 16 * p as u64 + 65 * c as u64
    }

    /// Refuses, before anything is allocated, time histories of `samples` samples of `p` modes
    /// and `c` contacts that do not fit in the memory available, `copies` times (a front end
    /// that copies them out, as the Python package into numpy arrays, needs two):
    /// `samples × (8 + 16 p + 65 c) × copies` bytes against the memory the system says is
    /// available (Linux: `MemAvailable`, and the control group's limit; elsewhere only what
    /// cannot be addressed is refused). The error names `output.every` and the fix.
    pub fn check_memory(samples: u64, p: usize, c: usize, copies: u64) -> Result<()> {
        let per_sample = Self::bytes_per_sample(p, c).saturating_mul(copies.max(1));
        let needed = samples.saturating_mul(per_sample);
        let available = available_memory().unwrap_or(isize::MAX as u64);
        if needed <= available {
            return Ok(());
        }
        // samples that fit in half the memory available: every step kept, k-th of them
        let fit = (available / 2 / per_sample.max(1)).max(1);
        let raise = samples.div_ceil(fit).max(2);
        Err(Error::invalid(
            "output.every",
            format!(
                "the run would keep {samples} output samples of {p} modes and {c} contacts in                  memory, {}{}, more than the {} available: keep fewer samples (multiply                  output.every by {raise} or more), or run the case with `fretdyn run`, which                  streams the time histories to disk",
                human_bytes(needed),
                if copies > 1 {
                    format!(" ({copies} copies)")
                } else {
                    String::new()
                },
                human_bytes(available)
            ),
        ))
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

/// Memory the system can give this process, bytes: `MemAvailable` of `/proc/meminfo`, bounded
/// by the control group's `memory.max − memory.current` (cgroup v2) when there is one; `None`
/// when neither is known.
fn available_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| {
            let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
            let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
            Some(kb.saturating_mul(1024))
        });
    let read = |name: &str| -> Option<u64> {
        std::fs::read_to_string(format!("/sys/fs/cgroup/{name}"))
            .ok()?
            .trim()
            .parse()
            .ok()
    };
    // "max" (no limit) does not parse
    let cgroup =
        read("memory.max").map(|max| max.saturating_sub(read("memory.current").unwrap_or(0)));
    match (meminfo, cgroup) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// `bytes` for a person: `1.5 GB` (powers of 1000).
pub(crate) fn human_bytes(bytes: u64) -> String {
    let units = ["bytes", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1000.0 && unit + 1 < units.len() {
        value /= 1000.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} bytes")
    } else {
        format!("{value:.1} {}", units[unit])
    }
}
