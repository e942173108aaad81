//! The path tracer's bounces against the one-bounce estimator it grew from:
//! one bounce must stay that estimator bit for bit, because the bench serves
//! truths cached before there were bounces as one-bounce truths.

use super::*;
use crate::scene::cornell::cornell_box;

/// The one-bounce estimator as it was before paths went on past the first
/// bounce, kept verbatim: `spp` cosine-weighted rays about one basis, each
/// adding the direct light leaving the surface it hits.
fn one_bounce_as_before(sh: &Shading, s: &SurfacePoint, spp: u32, rng: &mut Pcg) -> Vec3 {
    let n = s.normal;
    let sign = 1f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let t = Vec3A::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let bt = Vec3A::new(b, sign + n.y * n.y * a, -n.y);
    let origin = s.position + n * ray_offset(s.position);
    let mut sum = Vec3::ZERO;
    for _ in 0..spp {
        let (u1, u2) = (rng.uniform(), rng.uniform());
        let r = u1.sqrt();
        let phi = 2.0 * PI * u2;
        let dir = (t * (r * phi.cos()) + bt * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt())
            .normalize();
        if let Some(y) = sh.trace(origin, dir) {
            sum += sh.direct(&y);
        }
    }
    sum * (PI / spp as f32)
}

/// Surface points of the built-in box seen from its camera: a fan of rays
/// about the view direction.
fn seen(sh: &Shading) -> Vec<SurfacePoint> {
    let forward = Vec3A::from(sh.scene.camera.forward());
    let side = forward.cross(Vec3A::Y).normalize();
    let up = side.cross(forward);
    (0..64)
        .filter_map(|i| {
            let (x, y) = ((i % 8) as f32 / 7.0 - 0.5, (i / 8) as f32 / 7.0 - 0.5);
            sh.trace(
                Vec3A::ZERO,
                (forward + 0.6 * (x * side + y * up)).normalize(),
            )
        })
        .collect()
}

#[test]
fn one_bounce_is_the_one_bounce_estimator_bit_for_bit() {
    let scene = cornell_box();
    let sh = Shading::new(&scene);
    let points = seen(&sh);
    assert!(points.len() > 48, "{} points seen", points.len());
    let mut lit = 0;
    for (i, p) in points.iter().enumerate() {
        let (mut a, mut b) = (Pcg::new(7, i as u64), Pcg::new(7, i as u64));
        let layers = sh.indirect(p, 16, Bounces::ONE, &mut a);
        let before = one_bounce_as_before(&sh, p, 16, &mut b);
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        assert_eq!(bits(layers[0]), bits(before), "point {i}");
        lit += (layers[0].max_element() > 0.0) as usize;
        assert_eq!(layers[1..], [Vec3::ZERO; 3], "point {i}");
        // The same draws, no more: the generators are where each other is.
        assert_eq!(a.next(), b.next(), "point {i}");
    }
    // Compared on light, not on zeros: most of 16 rays' hits are lit.
    assert!(
        lit > points.len() / 2,
        "{lit} of {} points lit",
        points.len()
    );
}

#[test]
fn a_count_of_bounces_fills_its_layers_and_no_more() {
    let scene = cornell_box();
    let sh = Shading::new(&scene);
    let points = seen(&sh);
    for (bounces, filled) in [
        (Bounces::Count(2), 2),
        (Bounces::Count(3), 3),
        (Bounces::Count(6), 4),
        (Bounces::Infinite, 4),
    ] {
        let mut totals = [Vec3::ZERO; LAYERS];
        for (i, p) in points.iter().enumerate() {
            let mut rng = Pcg::new(3, i as u64);
            let layers = sh.indirect(p, 16, bounces, &mut rng);
            for (t, l) in totals.iter_mut().zip(layers) {
                assert!(l.min_element() >= 0.0, "{bounces:?} point {i}: {l}");
                *t += l;
            }
        }
        // Every bounce traced lights some point of the box (1,000 paths,
        // each of whose bounces sees lit walls), and none beyond.
        for (k, t) in totals.iter().enumerate() {
            assert_eq!(
                t.max_element() > 0.0,
                k < filled,
                "{bounces:?} layer {k}: {t}"
            );
        }
    }
}
