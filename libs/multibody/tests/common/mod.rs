//! Shared helpers for the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use sc_multibody::{Robot, Vector7, Vector13};

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

pub fn servicer() -> Robot {
    Robot::from_urdf_file(&root().join("config/servicer.urdf")).expect("servicer URDF loads")
}

pub fn generic() -> Robot {
    Robot::from_urdf_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/generic_arm.urdf"),
    )
    .expect("generic URDF loads")
}

/// Small deterministic PRNG (xorshift64*), uniform in [lo, hi).
pub struct Rng(u64);
impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    pub fn next_f64(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        (x >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }
    pub fn theta(&mut self, r: &Robot) -> Vector7 {
        let (lo, hi, _, _) = r.joint_limit_arrays();
        Vector7::from_fn(|i, _| self.uniform(lo[i], hi[i]))
    }
    pub fn vec7(&mut self, a: f64) -> Vector7 {
        Vector7::from_fn(|_, _| self.uniform(-a, a))
    }
    pub fn vec13(&mut self, a: f64) -> Vector13 {
        Vector13::from_fn(|_, _| self.uniform(-a, a))
    }
}

pub fn robots() -> Vec<(&'static str, Robot)> {
    vec![("servicer", servicer()), ("generic", generic())]
}
