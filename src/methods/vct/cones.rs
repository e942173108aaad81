//! The diffuse cone set (docs/algorithm.md section 9.3), as
//! `shaders/vct/trace.frag` builds it: one cone along the normal, of half
//! angle 30 degrees, and `k - 1` cones in a ring 60 degrees off the normal,
//! evenly spread in azimuth. Each cone stands for a part of the hemisphere
//! and its weight is that part's cosine-weighted solid angle, so that the
//! weights sum to `pi` (irradiance `E = sum w_k L_k` is `pi L` under a
//! uniform radiance `L`): the normal cone the cap within 30 degrees,
//! `pi sin^2 30 = pi / 4`, and the ring the rest, `3 pi / 4` shared equally.

use glam::DVec3;
use std::f64::consts::PI;

/// The cap of the normal cone, and the ring's angle off the normal.
pub const CAP_DEG: f64 = 30.0;
pub const RING_DEG: f64 = 60.0;

/// One cone: its axis in the frame whose z is the normal, tan of its half
/// angle, its weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    pub axis: DVec3,
    pub tan_half_angle: f64,
    pub weight: f64,
}

/// Half angle of the ring's cones: 30 degrees (they span the ring from 30
/// to 90 degrees off the normal), narrower where more than six share the
/// ring so that they do not overlap: half the arc between two neighbours,
/// `pi sin 60 / (k - 1)`.
pub fn ring_half_angle(k: u32) -> f64 {
    let between = PI * RING_DEG.to_radians().sin() / (k - 1) as f64;
    between.min(CAP_DEG.to_radians())
}

/// The `k` cones.
pub fn cones(k: u32) -> Vec<Cone> {
    let cap = CAP_DEG.to_radians();
    let ring = RING_DEG.to_radians();
    let mut out = vec![Cone {
        axis: DVec3::Z,
        tan_half_angle: cap.tan(),
        weight: PI * cap.sin().powi(2),
    }];
    for i in 0..k - 1 {
        let phi = 2.0 * PI * i as f64 / (k - 1) as f64;
        out.push(Cone {
            axis: DVec3::new(ring.sin() * phi.cos(), ring.sin() * phi.sin(), ring.cos()),
            tan_half_angle: ring_half_angle(k).tan(),
            weight: PI * cap.cos().powi(2) / (k - 1) as f64,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_pi_and_cones_stay_in_the_hemisphere() {
        for k in 5..=9 {
            let c = cones(k);
            assert_eq!(c.len(), k as usize);
            let sum: f64 = c.iter().map(|c| c.weight).sum();
            assert!((sum - PI).abs() < 1e-12, "{k}: {sum}");
            for cone in &c {
                // The cone's edge reaches the tangent plane at most.
                let edge = cone.axis.z.acos() + cone.tan_half_angle.atan();
                assert!(edge <= PI / 2.0 + 1e-9, "{k}: {edge}");
            }
        }
        // The classic six: pi / 4 along the normal, 3 pi / 20 each in the ring.
        let six = cones(6);
        assert!((six[0].weight - PI / 4.0).abs() < 1e-12);
        assert!((six[1].weight - 3.0 * PI / 20.0).abs() < 1e-12);
    }
}
