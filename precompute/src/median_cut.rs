//! The directional-light baseline: median-cut sampling (Debevec 2005, "A Median Cut Algorithm
//! for Light Probe Sampling"). The map is split into regions of equal light energy
//! (luminance × solid angle), each split across its longest side (the width measured with the
//! cosine of latitude), always splitting the region of most energy next so any N works; each
//! region becomes one light at its energy centroid carrying the region's ∫ L dω.
//! Sums use an f64 summed-area table, so large maps lose no precision.

use crate::envmap::EnvMap;
use glam::DVec3;

/// One directional light: unit direction toward the light and its power ∫ L dω per channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionalLight {
    pub direction: DVec3,
    pub power: [f64; 3],
}

#[derive(Clone, Copy, Debug)]
struct Region {
    x0: usize,
    y0: usize,
    x1: usize,
    y1: usize,
}

/// Summed-area table of luminance × solid angle.
struct EnergyTable {
    w: usize,
    sat: Vec<f64>,
}

impl EnergyTable {
    fn new(map: &EnvMap) -> Self {
        let (w, h) = (map.width(), map.height());
        let mut sat = vec![0.0; (w + 1) * (h + 1)];
        for y in 0..h {
            let da = map.row_solid_angle(y);
            let mut row = 0.0;
            for x in 0..w {
                row += luminance(map.pixel(x, y)) * da;
                sat[(y + 1) * (w + 1) + x + 1] = sat[y * (w + 1) + x + 1] + row;
            }
        }
        Self { w, sat }
    }
    fn sum(&self, r: Region) -> f64 {
        let s = |x: usize, y: usize| self.sat[y * (self.w + 1) + x];
        s(r.x1, r.y1) - s(r.x0, r.y1) - s(r.x1, r.y0) + s(r.x0, r.y0)
    }
}

fn luminance(p: [f32; 3]) -> f64 {
    strandlight_tables::colour::luminance(p.map(f64::from))
}

/// `count` lights (fewer only if the map has fewer pixels).
pub fn median_cut(map: &EnvMap, count: usize) -> Vec<DirectionalLight> {
    let table = EnergyTable::new(map);
    let mut regions = vec![Region {
        x0: 0,
        y0: 0,
        x1: map.width(),
        y1: map.height(),
    }];
    while regions.len() < count {
        // The most energetic region that can still be split (ties: first one; deterministic).
        let Some(i) = (0..regions.len())
            .filter(|&i| {
                let r = regions[i];
                r.x1 - r.x0 > 1 || r.y1 - r.y0 > 1
            })
            .max_by(|&a, &b| {
                table
                    .sum(regions[a])
                    .total_cmp(&table.sum(regions[b]))
                    .then(b.cmp(&a))
            })
        else {
            break;
        };
        let (a, b) = split(map, &table, regions[i]);
        regions[i] = a;
        regions.push(b);
    }
    regions.iter().map(|&r| light_of(map, r)).collect()
}

fn split(map: &EnvMap, table: &EnergyTable, r: Region) -> (Region, Region) {
    let mid_theta = std::f64::consts::PI * (r.y0 + r.y1) as f64 * 0.5 / map.height() as f64;
    let width = (r.x1 - r.x0) as f64 * mid_theta.sin();
    let height = (r.y1 - r.y0) as f64;
    let total = table.sum(r);
    let split_x = r.x1 - r.x0 > 1 && (width >= height || r.y1 - r.y0 == 1);
    // The cut that makes the first part's energy closest to half.
    let (lo, hi) = if split_x {
        (r.x0 + 1, r.x1)
    } else {
        (r.y0 + 1, r.y1)
    };
    let part = |c: usize| {
        if split_x {
            Region { x1: c, ..r }
        } else {
            Region { y1: c, ..r }
        }
    };
    let cut = (lo..hi)
        .min_by(|&a, &b| {
            let da = (table.sum(part(a)) - 0.5 * total).abs();
            let db = (table.sum(part(b)) - 0.5 * total).abs();
            da.total_cmp(&db)
        })
        .unwrap_or(lo);
    let rest = if split_x {
        Region { x0: cut, ..r }
    } else {
        Region { y0: cut, ..r }
    };
    (part(cut), rest)
}

fn light_of(map: &EnvMap, r: Region) -> DirectionalLight {
    let mut power = [0.0; 3];
    let mut centroid = DVec3::ZERO;
    for y in r.y0..r.y1 {
        let da = map.row_solid_angle(y);
        for x in r.x0..r.x1 {
            let p = map.pixel(x, y);
            (0..3).for_each(|c| power[c] += p[c] as f64 * da);
            centroid += map.direction(x, y) * (luminance(p) * da);
        }
    }
    if centroid.length() < 1e-300 {
        // A black region: its geometric center (it carries no power anyway).
        let (x, y) = ((r.x0 + r.x1) / 2, (r.y0 + r.y1) / 2);
        centroid = map.direction(x.min(map.width() - 1), y.min(map.height() - 1));
    }
    DirectionalLight {
        direction: centroid.normalize(),
        power,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lights_carry_the_whole_map_and_find_a_bright_pixel() {
        let mut px = vec![[0.2f32, 0.3, 0.4]; 128 * 64];
        px[20 * 128 + 90] = [4000.0, 3000.0, 2000.0];
        let map = EnvMap::from_pixels(128, 64, px);
        for n in [1, 7, 16, 64] {
            let lights = median_cut(&map, n);
            assert_eq!(lights.len(), n);
            let total: [f64; 3] = std::array::from_fn(|c| lights.iter().map(|l| l.power[c]).sum());
            let want = map.integral();
            eprintln!("median cut N={n}: Σ power {total:?} vs ∫L dω {want:?}");
            for c in 0..3 {
                assert!((total[c] - want[c]).abs() < 1e-9 * want[c]);
            }
        }
        // With enough lights the brightest one sits on the bright pixel.
        let lights = median_cut(&map, 64);
        let brightest = lights
            .iter()
            .max_by(|a, b| a.power[0].total_cmp(&b.power[0]))
            .unwrap();
        let angle = brightest
            .direction
            .dot(map.direction(90, 20))
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        eprintln!("brightest light is {angle:.2}° from the bright pixel");
        assert!(angle < 3.0);
    }
}
