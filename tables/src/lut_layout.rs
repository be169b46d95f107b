//! Where a table's nodes land in an exported GPU texture: the one layout rule of
//! `bake --export ktx2`, shared by the writer, its sidecar and every test that reads it back.
//!
//! Texture x varies fastest; node `i` of an axis sits at the centre of texel `i` along the
//! texture axis it maps to. With axes `a0 … a(d−1)` (counts `n0 …`):
//!
//! | axes | texture | texel of node `(i0, …)` |
//! | --- | --- | --- |
//! | 1 | 2D, `n0 × 1` | `(i0, 0)` |
//! | 2 | 2D, `n1 × n0` | `(i1, i0)` |
//! | 3 | 3D, `n2 × n1 × n0` | `(i2, i1, i0)` |
//! | 4 | 3D, `n2 × n1 × (n0·n3)` | `(i2, i1, i3·n0 + i0)`: one slab of `n0` slices per node of the fourth axis |
//!
//! Up to three axes this is the table's own memory order. A fourth axis (1/λ, σ̄_f) becomes
//! slabs stacked along z, so the hardware's trilinear filter interpolates the three direction
//! axes inside a slab, and the shader blends two slabs: WebGPU has no 3D array textures, and
//! stacking the 32·96 (u·ξ, u·ω_o) pairs instead would exceed its 2048-texel depth limit.

use crate::table::Axis;

/// How a table of up to four axes is laid out as a texture.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LutLayout {
    counts: Vec<usize>,
}

/// WebGPU's default `maxTextureDimension3D` (and Vulkan's guaranteed minimum for 3D images).
pub const MAX_3D_EXTENT: usize = 2048;
/// WebGPU's default `maxTextureDimension2D`.
pub const MAX_2D_EXTENT: usize = 8192;

impl LutLayout {
    /// The layout of a table with these axes; `None` for more than four axes.
    pub fn of(axes: &[Axis]) -> Option<Self> {
        (1..=4).contains(&axes.len()).then(|| Self {
            counts: axes.iter().map(|a| a.count).collect(),
        })
    }

    pub fn is_3d(&self) -> bool {
        self.counts.len() >= 3
    }

    /// (width, height, depth); depth 0 for a 2D texture, as KTX2 writes it.
    pub fn extent(&self) -> [usize; 3] {
        match self.counts[..] {
            [n0] => [n0, 1, 0],
            [n0, n1] => [n1, n0, 0],
            [n0, n1, n2] => [n2, n1, n0],
            [n0, n1, n2, n3] => [n2, n1, n0 * n3],
            _ => unreachable!("a layout has 1 to 4 axes"),
        }
    }

    /// The largest extent against what WebGPU guarantees for this kind of texture.
    pub fn exceeds_webgpu_limits(&self) -> Option<(usize, usize)> {
        let largest = self.extent().into_iter().max().unwrap_or(0);
        let limit = if self.is_3d() {
            MAX_3D_EXTENT
        } else {
            MAX_2D_EXTENT
        };
        (largest > limit).then_some((largest, limit))
    }

    /// The texel (x, y, z) holding node `index`.
    pub fn texel(&self, index: &[usize]) -> [usize; 3] {
        match (index, &self.counts[..]) {
            ([i0], _) => [*i0, 0, 0],
            ([i0, i1], _) => [*i1, *i0, 0],
            ([i0, i1, i2], _) => [*i2, *i1, *i0],
            ([i0, i1, i2, i3], [n0, ..]) => [*i2, *i1, i3 * n0 + i0],
            _ => panic!(
                "node index {index:?} does not fit the layout {:?}",
                self.counts
            ),
        }
    }

    /// Offset of a texel in the texture's texel order (x fastest).
    pub fn texel_offset(&self, texel: [usize; 3]) -> usize {
        let [w, h, _] = self.extent();
        (texel[2] * h + texel[1]) * w + texel[0]
    }

    /// The prose of the rule for this table, for the sidecar.
    pub fn describe(&self) -> String {
        match self.counts.len() {
            1 => "2D texture n0 × 1: texel (i0, 0)".into(),
            2 => "2D texture n1 × n0: texel (x, y) = (i1, i0)".into(),
            3 => "3D texture n2 × n1 × n0: texel (x, y, z) = (i2, i1, i0)".into(),
            _ => "3D texture n2 × n1 × (n0·n3): texel (x, y, z) = (i2, i1, i3·n0 + i0), i.e. one slab of n0 z-slices per node i3 of the fourth axis".into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axes(counts: &[usize]) -> Vec<Axis> {
        counts
            .iter()
            .enumerate()
            .map(|(k, &n)| Axis::uniform(format!("a{k}"), 0.0, 1.0, n))
            .collect()
    }

    /// Every node lands on its own texel, and every texel holds a node.
    #[test]
    fn nodes_and_texels_correspond_one_to_one() {
        for counts in [&[5][..], &[3, 4], &[3, 4, 5], &[3, 4, 5, 2], &[2, 3, 4, 1]] {
            let layout = LutLayout::of(&axes(counts)).unwrap();
            let [w, h, d] = layout.extent();
            let total = w * h.max(1) * d.max(1);
            assert_eq!(total, counts.iter().product::<usize>(), "{counts:?}");
            let mut seen = vec![false; total];
            let mut index = vec![0; counts.len()];
            for _ in 0..total {
                let offset = layout.texel_offset(layout.texel(&index));
                assert!(!seen[offset], "{counts:?}: two nodes on texel {offset}");
                seen[offset] = true;
                for k in (0..counts.len()).rev() {
                    index[k] += 1;
                    if index[k] < counts[k] {
                        break;
                    }
                    index[k] = 0;
                }
            }
        }
    }

    #[test]
    fn the_fourth_axis_becomes_slabs_along_z() {
        let layout = LutLayout::of(&axes(&[32, 96, 32, 16])).unwrap();
        assert_eq!(layout.extent(), [32, 96, 512]);
        assert_eq!(layout.texel(&[5, 7, 9, 3]), [9, 7, 3 * 32 + 5]);
        assert_eq!(layout.exceeds_webgpu_limits(), None);
        let deep = LutLayout::of(&axes(&[64, 8, 8, 64])).unwrap();
        assert_eq!(deep.exceeds_webgpu_limits(), Some((4096, 2048)));
        assert!(LutLayout::of(&axes(&[2, 2, 2, 2, 2])).is_none());
    }
}
