//! Coarser strands for passes that cannot see their detail. A κ-simplified light map (Ren 2010
//! §7) is drawn at a fraction of the full map's texels with fibers 1/κ times wider, so a strand
//! point that lies within a fraction of such a texel of the chord between its neighbours changes
//! nothing the map can hold, yet on a software rasterizer every segment costs a quad
//! (docs/BENCHMARKS.md, "Coarser strands in the simplified light pass"). A chord is shorter than
//! the curl it replaces, so its fiber is widened by the ratio: the strand keeps its drawn area
//! (length × width), hence the optical depth it adds to a map, where curls are finer than a texel.

use glam::Vec3;

use super::{Attribute, HairModel};

/// The most original segments one kept segment may replace: bounds the greedy search's cost on
/// long, straight strands (quadratic in the run) while already cutting their segments 16-fold.
const MAX_MERGED_SEGMENTS: usize = 16;

impl HairModel {
    /// The model with every strand's interior points dropped wherever each dropped point lies
    /// within `tolerance` (world units) of the kept segment that replaces it. Roots and tips
    /// are kept, as is every strand; transparency and colour follow their points; thickness
    /// (`thickness_where_none` where the model has none) is scaled at each kept point by the
    /// arc-to-chord length ratio of the segments beside it. A tolerance that is not positive
    /// and finite keeps the model as it is.
    pub fn decimated(&self, tolerance: f32, thickness_where_none: f32) -> HairModel {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return self.clone();
        }
        let mut kept = Vec::with_capacity(self.point_count());
        let mut widening = Vec::with_capacity(self.point_count());
        let mut offsets = Vec::with_capacity(self.strand_count() + 1);
        offsets.push(0u32);
        for (s, strand) in self.strands().enumerate() {
            let first = self.strand_offsets()[s] as usize;
            let strand_kept: Vec<usize> = kept_points(strand, tolerance).collect();
            widening.extend(arc_to_chord_at_points(strand, &strand_kept));
            kept.extend(strand_kept.iter().map(|&i| first + i));
            offsets.push(kept.len() as u32);
        }
        let points = kept.iter().map(|&i| self.points()[i]).collect();
        let thickness = kept
            .iter()
            .zip(&widening)
            .map(|(&i, w)| w * self.thickness().map_or(thickness_where_none, |t| t.at(i)))
            .collect();
        HairModel::new(
            points,
            offsets,
            Some(Attribute::PerPoint(thickness)),
            self.transparency().map(|a| a.at_points(&kept)),
            self.color().map(|c| c.at_points(&kept)),
        )
        .expect("a subset of a valid model's points, roots and tips kept, is valid")
    }
}

/// Per kept point of a strand: the mean arc-to-chord length ratio of the kept segments beside it
/// (1 for a segment of zero length).
fn arc_to_chord_at_points(strand: &[Vec3], kept: &[usize]) -> Vec<f32> {
    let ratios: Vec<f32> = kept
        .windows(2)
        .map(|w| {
            let chord = strand[w[0]].distance(strand[w[1]]);
            let arc: f32 = strand[w[0]..=w[1]]
                .windows(2)
                .map(|p| p[0].distance(p[1]))
                .sum();
            if chord > 0.0 { arc / chord } else { 1.0 }
        })
        .collect();
    (0..kept.len())
        .map(|k| {
            let before = k.checked_sub(1).map(|j| ratios[j]);
            let after = ratios.get(k).copied();
            match (before, after) {
                (Some(a), Some(b)) => 0.5 * (a + b),
                (Some(r), None) | (None, Some(r)) => r,
                (None, None) => 1.0,
            }
        })
        .collect()
}

/// Indices into `strand` of the points kept: greedily, from each kept point the farthest point
/// (at most [`MAX_MERGED_SEGMENTS`] on) whose chord passes within `tolerance` of every point
/// between.
fn kept_points(strand: &[Vec3], tolerance: f32) -> impl Iterator<Item = usize> + '_ {
    let last = strand.len() - 1;
    let mut anchor = Some(0usize);
    std::iter::from_fn(move || {
        let current = anchor?;
        anchor = (current < last).then(|| farthest_end(strand, current, tolerance));
        Some(current)
    })
}

/// The farthest end `e` (> `start`) whose segment from `start` passes within `tolerance` of
/// every point strictly between.
fn farthest_end(strand: &[Vec3], start: usize, tolerance: f32) -> usize {
    let limit = (start + MAX_MERGED_SEGMENTS).min(strand.len() - 1);
    let mut end = start + 1;
    for candidate in start + 2..=limit {
        let (a, b) = (strand[start], strand[candidate]);
        let close = strand[start + 1..candidate]
            .iter()
            .all(|&p| distance_to_segment(p, a, b) <= tolerance);
        if !close {
            break;
        }
        end = candidate;
    }
    end
}

fn distance_to_segment(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let length_squared = ab.length_squared();
    let t = match length_squared > 0.0 {
        true => ((p - a).dot(ab) / length_squared).clamp(0.0, 1.0),
        false => 0.0,
    };
    p.distance(a + t * ab)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model(strands: &[Vec<Vec3>]) -> HairModel {
        let mut offsets = vec![0u32];
        let points: Vec<Vec3> = strands.iter().flatten().copied().collect();
        for s in strands {
            offsets.push(offsets.last().unwrap() + s.len() as u32);
        }
        let thickness = Attribute::PerPoint((0..points.len()).map(|i| i as f32).collect());
        HairModel::new(points, offsets, Some(thickness), None, None).unwrap()
    }

    fn helix(points: usize, turns: f32) -> Vec<Vec3> {
        (0..points)
            .map(|i| {
                let t = i as f32 / (points - 1) as f32;
                let a = std::f32::consts::TAU * turns * t;
                Vec3::new(a.cos(), a.sin(), 3.0 * t)
            })
            .collect()
    }

    /// Distance from `p` to the polyline `kept`, brute force in f64 over 4096 samples per
    /// segment (independent of the search's closed form), and the most the sampling can
    /// overestimate it by (half the longest sample spacing).
    fn sampled_distance(p: Vec3, kept: &[Vec3]) -> (f64, f64) {
        const SAMPLES: usize = 4096;
        let (p, mut best, mut step) = (p.as_dvec3(), f64::INFINITY, 0.0f64);
        for w in kept.windows(2) {
            let (a, b) = (w[0].as_dvec3(), w[1].as_dvec3());
            step = step.max(a.distance(b) / (2 * SAMPLES) as f64);
            for k in 0..=SAMPLES {
                best = best.min(p.distance(a.lerp(b, k as f64 / SAMPLES as f64)));
            }
        }
        (best, step)
    }

    #[test]
    fn a_straight_strand_keeps_its_root_and_tip() {
        let line: Vec<Vec3> = (0..9).map(|i| Vec3::new(0.0, 0.0, i as f32)).collect();
        let m = model(&[line]).decimated(1e-3, 1.0);
        assert_eq!(m.points(), [Vec3::ZERO, Vec3::new(0.0, 0.0, 8.0)]);
        // Attributes follow their points (thickness was the original index), a straight chord
        // as long as its arc.
        assert_eq!(m.thickness(), Some(&Attribute::PerPoint(vec![0.0, 8.0])));
    }

    #[test]
    fn every_dropped_point_lies_within_the_tolerance_of_the_coarse_strand() {
        let original = model(&[helix(200, 3.0), helix(7, 0.1), helix(2, 1.0)]);
        for tolerance in [1e-3, 0.02, 0.2] {
            let coarse = original.decimated(tolerance, 1.0);
            assert_eq!(coarse.strand_count(), 3);
            for (fine, kept) in original.strands().zip(coarse.strands()) {
                assert_eq!(
                    (fine[0], fine[fine.len() - 1]),
                    (kept[0], kept[kept.len() - 1])
                );
                for &p in fine {
                    let (d, step) = sampled_distance(p, kept);
                    assert!(
                        d <= tolerance as f64 * 1.0001 + step,
                        "{p} is {d} from the coarse strand"
                    );
                }
            }
        }
        // A tighter tolerance keeps more of the helix, a looser one less.
        let counts: Vec<_> = [1e-3, 0.02, 0.2]
            .map(|t| original.decimated(t, 1.0).point_count())
            .into();
        assert!(counts[0] > counts[1] && counts[1] > counts[2], "{counts:?}");
    }

    #[test]
    fn long_straight_runs_are_cut_into_bounded_pieces() {
        let line: Vec<Vec3> = (0..=40).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect();
        let m = model(&[line]).decimated(1.0, 1.0);
        let xs: Vec<f32> = m.points().iter().map(|p| p.x).collect();
        assert_eq!(xs, [0.0, 16.0, 32.0, 40.0]);
    }

    /// A fine zigzag replaced by its axis: the chord's fiber is widened so that length × width,
    /// the area it draws, stays the zigzag's (here with the model's default thickness).
    #[test]
    fn a_chord_is_widened_to_keep_the_area_of_the_curl_it_replaces() {
        let zigzag: Vec<Vec3> = (0..=8)
            .map(|i| Vec3::new(i as f32, if i % 2 == 1 { 0.1 } else { 0.0 }, 0.0))
            .collect();
        let arc: f32 = zigzag.windows(2).map(|w| w[0].distance(w[1])).sum();
        let bare = HairModel::new(zigzag, vec![0, 9], None, None, None).unwrap();
        let m = bare.decimated(0.2, 0.5);
        assert_eq!(m.point_count(), 2);
        let Some(Attribute::PerPoint(t)) = m.thickness() else {
            panic!("thickness per point expected")
        };
        let drawn_area = 8.0 * 0.5 * (t[0] + t[1]);
        assert!(
            (drawn_area - arc * 0.5).abs() < 1e-5 * arc,
            "{drawn_area} vs {}",
            arc * 0.5
        );
    }

    #[test]
    fn no_tolerance_keeps_every_point() {
        let original = model(&[helix(20, 1.0)]);
        for tolerance in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert_eq!(original.decimated(tolerance, 1.0), original);
        }
    }
}
