//! Pictures of a table: 2D slices tiled into one image, as in Ren 2010 Fig. 3 (slices of the
//! 4D convolution I_M, one small square per λ). Written as EXR (linear values, exactly the
//! table's) and PNG (tonemapped for looking at; the operator is named in the PNG's text chunks
//! and returned by [`SlicePicture::write_png`]).
//!
//! # Placement (what the pixel at (x, y) shows)
//!
//! Image rows are stored top first. Each tile shows one 2D slice: the tile's x axis grows left
//! to right and its y axis grows **bottom to top** (as in a plot and in the paper's figure);
//! each node is a `pixels_per_node`² block. Tiles are separated and surrounded by `gap` pixels.
//! Tile column `c` (from the left) and tile row `r` (from the bottom) start at
//!
//! ```text
//! left = gap + c·(tile_width + gap)        tile_width  = n_x · pixels_per_node
//! top  = gap + (rows − 1 − r)·(tile_height + gap)   tile_height = n_y · pixels_per_node
//! ```
//!
//! and node `(i_x, i_y)` of the tile covers `left + i_x·s … +s`, `top + (n_y − 1 − i_y)·s … +s`.
//! [`TileGrid`] says which axes choose `c` and `r`; every other axis is held at a fixed node.
//!
//! Colours: a 1-channel table is shown gray (R = G = B), a 3-channel table as RGB. Gap pixels
//! are 0 in the EXR and dark blue [`PNG_GAP_COLOR`] in the PNG; non-finite values stay as they
//! are in the EXR and are magenta [`PNG_NON_FINITE_COLOR`] in the PNG.

use crate::colour::srgb_encode;
use crate::image_out::{ImageWriteError, write_exr_rgb, write_png_rgb8_with_text};
use crate::table::{Axis, Table};
use std::path::Path;
use thiserror::Error;

/// Largest picture side in pixels (keeps PNG viewers and memory sane).
pub const MAX_SIDE: u64 = 1 << 15;
pub const PNG_GAP_COLOR: [u8; 3] = [24, 24, 72];
pub const PNG_NON_FINITE_COLOR: [u8; 3] = [255, 0, 255];

#[derive(Debug, Error)]
pub enum SliceError {
    #[error("slice layout: {0}")]
    InvalidLayout(String),
    #[error("slice picture would be {width} × {height} pixels; at most {MAX_SIDE} per side")]
    TooLarge { width: u64, height: u64 },
    #[error(transparent)]
    Write(#[from] ImageWriteError),
}

/// Which axes step from tile to tile.
#[derive(Debug, Clone, PartialEq)]
pub enum TileGrid {
    /// One tile.
    Single,
    /// Tile columns step through the nodes of axis `columns` (left to right), tile rows through
    /// those of axis `rows` (bottom to top).
    Axes { columns: usize, rows: usize },
    /// The nodes of one axis, `columns` per row: left to right, then bottom to top (the
    /// arrangement of Ren 2010 Fig. 3, where the axis is 1/λ).
    Wrapped { axis: usize, columns: usize },
}

/// How a table is cut into the slices of a picture. Every axis must appear exactly once: as a
/// tile axis, a grid axis or a fixed axis.
#[derive(Debug, Clone, PartialEq)]
pub struct SliceLayout {
    /// Axis along a tile's width.
    pub x_axis: usize,
    /// Axis along a tile's height (`None` for a 1-D table: tiles one pixel row high).
    pub y_axis: Option<usize>,
    pub grid: TileGrid,
    /// `(axis, node index)` for every remaining axis.
    pub fixed: Vec<(usize, usize)>,
    pub pixels_per_node: u32,
    pub gap: u32,
}

impl SliceLayout {
    /// Tiles show axes 0 (x) and 1 (y) — for I_M, `u·ξ` and `u·ω_o`, the lobe structure of the
    /// paper's figure; a third axis is wrapped into a near-square grid; with four or more axes,
    /// tile columns step through axis 2 and tile rows through axis 3 (for I_M: cos(φ_ξ − φ_o)
    /// and 1/λ), further axes held at their middle node. Small tiles are enlarged to ≥ 16 px.
    pub fn default_for(table: &Table) -> Self {
        let counts: Vec<usize> = table.axes().iter().map(|a| a.count).collect();
        let d = counts.len();
        let (y_axis, grid) = match d {
            1 => (None, TileGrid::Single),
            2 => (Some(1), TileGrid::Single),
            3 => {
                let columns = (counts[2] as f64).sqrt().ceil() as usize;
                (Some(1), TileGrid::Wrapped { axis: 2, columns })
            }
            _ => (
                Some(1),
                TileGrid::Axes {
                    columns: 2,
                    rows: 3,
                },
            ),
        };
        let fixed = (4..d).map(|k| (k, counts[k] / 2)).collect();
        let largest = counts[0].max(y_axis.map_or(1, |y| counts[y]));
        let pixels_per_node = 16usize.div_ceil(largest).max(1) as u32;
        Self {
            x_axis: 0,
            y_axis,
            grid,
            fixed,
            pixels_per_node,
            gap: 1,
        }
    }
}

/// A rectangle of the picture and the grid/fixed node indices its slice is taken at.
#[derive(Debug, Clone, PartialEq)]
pub struct Tile {
    pub left: u32,
    pub top: u32,
    pub width: u32,
    pub height: u32,
    /// `(axis, node index)` of every axis held constant in this tile, grid axes included.
    pub held: Vec<(usize, usize)>,
}

/// A tiled picture of a table's slices, in linear values, ready to be written.
#[derive(Debug, Clone)]
pub struct SlicePicture {
    pub width: u32,
    pub height: u32,
    /// Linear RGB, row-major, top row first.
    pub pixels: Vec<[f32; 3]>,
    /// True where a pixel belongs to no tile.
    pub is_gap: Vec<bool>,
    pub tiles: Vec<Tile>,
    /// The largest finite value of the whole table (all channels): the PNG's white.
    pub table_max: f32,
    /// Human-readable layout, stored in both files' metadata.
    pub description: String,
}

/// How the PNG maps linear values to 8-bit codes. Both divide by the table maximum first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PngTonemap {
    /// `p = clamp(v / max, 0, 1)`, then the sRGB transfer curve.
    LinearSrgb,
    /// `p = clamp(1 + log10(v / max) / decades, 0, 1)` written as is: shows `decades` orders of
    /// magnitude below the maximum (useful for peaked lobes); v ≤ 0 is black.
    Log10 { decades: f32 },
}

impl PngTonemap {
    pub fn describe(&self, table_max: f32) -> String {
        match self {
            PngTonemap::LinearSrgb => format!(
                "linear: p = clamp(v / {table_max:e}, 0, 1) (table maximum), sRGB transfer curve, 8 bit"
            ),
            PngTonemap::Log10 { decades } => format!(
                "log10: p = clamp(1 + log10(v / {table_max:e}) / {decades}, 0, 1) (table maximum, {decades} decades), 8 bit, no transfer curve"
            ),
        }
    }

    fn code(&self, v: f32, table_max: f32) -> u8 {
        let ratio = v as f64 / table_max as f64;
        let p = match *self {
            PngTonemap::LinearSrgb => srgb_encode(ratio.clamp(0.0, 1.0)),
            PngTonemap::Log10 { decades } if ratio > 0.0 => {
                (1.0 + ratio.log10() / decades as f64).clamp(0.0, 1.0)
            }
            PngTonemap::Log10 { .. } => 0.0,
        };
        (p * 255.0).round() as u8
    }
}

impl SlicePicture {
    pub fn render(table: &Table, layout: &SliceLayout) -> Result<Self, SliceError> {
        let shape = Shape::check(table.axes(), layout)?;
        let (width, height) = (shape.width as usize, shape.height as usize);
        let mut pixels = vec![[0.0f32; 3]; width * height];
        let mut is_gap = vec![true; width * height];
        let mut tiles = Vec::new();
        let s = layout.pixels_per_node as usize;
        let mut index = vec![0usize; table.axes().len()];
        for &(axis, node) in &layout.fixed {
            index[axis] = node;
        }
        for (column, row, grid_held) in shape.tile_cells(layout) {
            let left = layout.gap as usize + column * (shape.tile_width + layout.gap as usize);
            let top = layout.gap as usize
                + (shape.rows - 1 - row) * (shape.tile_height + layout.gap as usize);
            for &(axis, node) in &grid_held {
                index[axis] = node;
            }
            for iy in 0..shape.ny {
                if let Some(y) = layout.y_axis {
                    index[y] = iy;
                }
                for ix in 0..shape.nx {
                    index[layout.x_axis] = ix;
                    let rgb = rgb_of(
                        table
                            .node(&index)
                            .expect("layout checked against the shape"),
                    );
                    let (px, py) = (left + ix * s, top + (shape.ny - 1 - iy) * s);
                    for y in py..py + s {
                        for x in px..px + s {
                            pixels[y * width + x] = rgb;
                            is_gap[y * width + x] = false;
                        }
                    }
                }
            }
            let mut held = layout.fixed.clone();
            held.extend(grid_held);
            held.sort();
            tiles.push(Tile {
                left: left as u32,
                top: top as u32,
                width: shape.tile_width as u32,
                height: shape.tile_height as u32,
                held,
            });
        }
        let stats = table.stats();
        let table_max = if stats.max > 0.0 { stats.max } else { 1.0 };
        let description = describe(table, layout, &shape);
        Ok(Self {
            width: shape.width,
            height: shape.height,
            pixels,
            is_gap,
            tiles,
            table_max,
            description,
        })
    }

    /// Linear float RGB EXR (ZIP-compressed, lossless), written atomically.
    pub fn write_exr(&self, path: &Path) -> Result<(), SliceError> {
        Ok(write_exr_rgb(
            path,
            self.width,
            self.height,
            &self.pixels,
            "table slices",
            &self.description,
        )?)
    }

    /// 8-bit RGB PNG tonemapped with `tonemap`, written atomically; returns the description
    /// of the tonemap that is also stored in the PNG's `Tonemap` text chunk.
    pub fn write_png(&self, path: &Path, tonemap: PngTonemap) -> Result<String, SliceError> {
        let mut bytes = Vec::with_capacity(self.pixels.len() * 3);
        for (rgb, &gap) in self.pixels.iter().zip(&self.is_gap) {
            let code = if gap {
                PNG_GAP_COLOR
            } else if rgb.iter().any(|v| !v.is_finite()) {
                PNG_NON_FINITE_COLOR
            } else {
                rgb.map(|v| tonemap.code(v, self.table_max))
            };
            bytes.extend_from_slice(&code);
        }
        let tonemap_text = tonemap.describe(self.table_max);
        write_png_rgb8_with_text(
            path,
            self.width,
            self.height,
            &bytes,
            &[
                ("Description", &self.description),
                ("Tonemap", &tonemap_text),
            ],
        )?;
        Ok(tonemap_text)
    }
}

/// Renders `table` with `layout` and writes both pictures; returns the picture and the PNG's
/// tonemap description.
pub fn write_slices(
    table: &Table,
    layout: &SliceLayout,
    exr_path: &Path,
    png_path: &Path,
    tonemap: PngTonemap,
) -> Result<(SlicePicture, String), SliceError> {
    let picture = SlicePicture::render(table, layout)?;
    picture.write_exr(exr_path)?;
    let tonemap_text = picture.write_png(png_path, tonemap)?;
    Ok((picture, tonemap_text))
}

fn rgb_of(values: &[f32]) -> [f32; 3] {
    match values {
        [v] => [*v; 3],
        [r, g, b] => [*r, *g, *b],
        _ => unreachable!("tables have 1 or 3 channels"),
    }
}

/// A tile's column, its row counted from the bottom, and the grid axes' node indices in it.
type TileCell = (usize, usize, Vec<(usize, usize)>);

/// Sizes derived from a checked layout.
struct Shape {
    nx: usize,
    ny: usize,
    columns: usize,
    rows: usize,
    tile_width: usize,
    tile_height: usize,
    width: u32,
    height: u32,
    counts: Vec<usize>,
}

impl Shape {
    fn check(axes: &[Axis], layout: &SliceLayout) -> Result<Self, SliceError> {
        let counts: Vec<usize> = axes.iter().map(|a| a.count).collect();
        let d = counts.len();
        let invalid = |m: String| Err(SliceError::InvalidLayout(m));
        let mut used: Vec<usize> = vec![layout.x_axis];
        used.extend(layout.y_axis);
        match layout.grid {
            TileGrid::Single => {}
            TileGrid::Axes { columns, rows } => used.extend([columns, rows]),
            TileGrid::Wrapped { axis, columns } => {
                if columns == 0 {
                    return invalid("a wrapped grid needs at least one column".into());
                }
                used.push(axis);
            }
        }
        for &(axis, node) in &layout.fixed {
            if axis < d && node >= counts[axis] {
                return invalid(format!(
                    "fixed node {node} of axis {axis} ({}) is beyond its {} nodes",
                    axes[axis].name, counts[axis]
                ));
            }
            used.push(axis);
        }
        let mut sorted = used.clone();
        sorted.sort();
        if sorted != (0..d).collect::<Vec<_>>() {
            return invalid(format!(
                "axes used {used:?} must name each of the table's {d} axes exactly once (tile x, tile y, grid, fixed)"
            ));
        }
        if layout.pixels_per_node == 0 {
            return invalid("pixels_per_node must be at least 1".into());
        }
        let (nx, ny) = (
            counts[layout.x_axis],
            layout.y_axis.map_or(1, |y| counts[y]),
        );
        let (columns, rows) = match layout.grid {
            TileGrid::Single => (1, 1),
            TileGrid::Axes { columns, rows } => (counts[columns], counts[rows]),
            TileGrid::Wrapped { axis, columns } => {
                (columns.min(counts[axis]), counts[axis].div_ceil(columns))
            }
        };
        let s = layout.pixels_per_node as u64;
        let gap = layout.gap as u64;
        let side = |tiles: usize, nodes: usize| {
            (nodes as u64)
                .saturating_mul(s)
                .saturating_add(gap)
                .saturating_mul(tiles as u64)
                .saturating_add(gap)
        };
        let (width, height) = (side(columns, nx), side(rows, ny));
        if width > MAX_SIDE || height > MAX_SIDE {
            return Err(SliceError::TooLarge { width, height });
        }
        Ok(Self {
            nx,
            ny,
            columns,
            rows,
            tile_width: nx * s as usize,
            tile_height: ny * s as usize,
            width: width as u32,
            height: height as u32,
            counts,
        })
    }

    /// (tile column, tile row from the bottom, grid axes' node indices) for every tile.
    fn tile_cells(&self, layout: &SliceLayout) -> Vec<TileCell> {
        match layout.grid {
            TileGrid::Single => vec![(0, 0, vec![])],
            TileGrid::Axes { columns, rows } => (0..self.rows)
                .flat_map(|r| (0..self.columns).map(move |c| (c, r, vec![(columns, c), (rows, r)])))
                .collect(),
            TileGrid::Wrapped { axis, columns } => (0..self.counts[axis])
                .map(|k| (k % columns, k / columns, vec![(axis, k)]))
                .collect(),
        }
    }
}

fn describe(table: &Table, layout: &SliceLayout, shape: &Shape) -> String {
    let axes = table.axes();
    let span = |k: usize| {
        let a = &axes[k];
        format!("`{}` [{}, {}] ({} nodes)", a.name, a.min, a.max, a.count)
    };
    let mut text = format!(
        "{}-D table, {} channel(s) ({}). Each tile: x = {} left to right",
        axes.len(),
        table.channels(),
        if table.channels() == 1 { "gray" } else { "RGB" },
        span(layout.x_axis)
    );
    if let Some(y) = layout.y_axis {
        text += &format!(", y = {} bottom to top", span(y));
    }
    text += &format!(
        "; {} px per node, {} px gaps. ",
        layout.pixels_per_node, layout.gap
    );
    match layout.grid {
        TileGrid::Single => text += "One tile.",
        TileGrid::Axes { columns, rows } => {
            text += &format!(
                "Tile columns: {} left to right; tile rows: {} bottom to top.",
                span(columns),
                span(rows)
            )
        }
        TileGrid::Wrapped { axis, columns } => {
            text += &format!(
                "Tiles: {} in node order, {} per row, left to right then bottom to top.",
                span(axis),
                columns.min(shape.counts[axis])
            )
        }
    }
    for &(axis, node) in &layout.fixed {
        text += &format!(
            " Fixed: `{}` = {} (node {node}).",
            axes[axis].name,
            axes[axis].node(node)
        );
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::atomic_write::tests::scratch_dir;

    /// Distinct value per node and channel, from the node index alone.
    fn value(index: &[usize], channel: usize) -> f32 {
        1.0 + (index[0] + 3 * index[1] + 12 * index[2] + 24 * index.get(3).copied().unwrap_or(0))
            as f32
            + 0.25 * channel as f32
    }

    fn table(shape: &[usize], channels: usize) -> Table {
        let axes: Vec<Axis> = shape
            .iter()
            .enumerate()
            .map(|(k, &n)| Axis::uniform(format!("a{k}·ξ"), 0.0, (n - 1) as f64, n))
            .collect();
        // Node coordinates equal node indices on these axes.
        Table::from_fn(axes, channels, |x, out| {
            let index: Vec<usize> = x.iter().map(|&v| v as usize).collect();
            for (c, o) in out.iter_mut().enumerate() {
                *o = value(&index, c);
            }
        })
        .unwrap()
    }

    fn read_exr(path: &Path) -> (usize, usize, Vec<[f32; 3]>) {
        let image = exr::prelude::read_first_rgba_layer_from_file(
            path,
            |size, _| {
                (
                    size.width(),
                    size.height(),
                    vec![[0.0f32; 3]; size.width() * size.height()],
                )
            },
            |(w, _, px): &mut (usize, usize, Vec<[f32; 3]>),
             p,
             (r, g, b, _a): (f32, f32, f32, f32)| {
                px[p.y() * *w + p.x()] = [r, g, b]
            },
        )
        .unwrap();
        image.layer_data.channel_data.pixels
    }

    /// sRGB encoding written from IEC 61966-2-1, for the expected PNG codes.
    fn srgb_code(linear: f64) -> u8 {
        let p = linear.clamp(0.0, 1.0);
        let e = if p <= 0.0031308 {
            12.92 * p
        } else {
            1.055 * p.powf(1.0 / 2.4) - 0.055
        };
        (255.0 * e).round() as u8
    }

    #[test]
    fn a_4d_table_lands_where_the_documented_layout_says() {
        let dir = scratch_dir("slices-4d");
        let shape = [3, 4, 2, 3];
        let t = table(&shape, 3);
        let layout = SliceLayout {
            x_axis: 0,
            y_axis: Some(1),
            grid: TileGrid::Axes {
                columns: 2,
                rows: 3,
            },
            fixed: vec![],
            pixels_per_node: 2,
            gap: 1,
        };
        let (exr_path, png_path) = (dir.join("s.exr"), dir.join("s.png"));
        let (picture, tonemap) =
            write_slices(&t, &layout, &exr_path, &png_path, PngTonemap::LinearSrgb).unwrap();
        eprintln!("{}\n{tonemap}", picture.description);
        let (s, gap) = (2usize, 1usize);
        let (tile_w, tile_h) = (3 * s, 4 * s);
        let (width, height) = (gap + 2 * (tile_w + gap), gap + 3 * (tile_h + gap));
        assert_eq!(
            (picture.width as usize, picture.height as usize),
            (width, height)
        );

        let (w, h, exr) = read_exr(&exr_path);
        assert_eq!((w, h), (width, height));
        let png = image::open(&png_path).unwrap().to_rgb8();
        assert_eq!(png.dimensions(), (width as u32, height as u32));
        let max = value(&[2, 3, 1, 2], 2) as f64; // the largest node value

        let mut covered = vec![false; width * height];
        for i3 in 0..3 {
            for i2 in 0..2 {
                for i1 in 0..4 {
                    for i0 in 0..3 {
                        // Tile (column i2, row i3 from the bottom); node y grows upward.
                        let left = gap + i2 * (tile_w + gap) + i0 * s;
                        let top = gap + (2 - i3) * (tile_h + gap) + (3 - i1) * s;
                        let want: [f32; 3] = std::array::from_fn(|c| value(&[i0, i1, i2, i3], c));
                        for y in top..top + s {
                            for x in left..left + s {
                                assert_eq!(exr[y * width + x], want, "EXR at ({x}, {y})");
                                let code = png.get_pixel(x as u32, y as u32).0;
                                assert_eq!(
                                    code,
                                    want.map(|v| srgb_code(v as f64 / max)),
                                    "PNG at ({x}, {y})"
                                );
                                covered[y * width + x] = true;
                            }
                        }
                    }
                }
            }
        }
        for (i, c) in covered.iter().enumerate() {
            if !c {
                assert_eq!(exr[i], [0.0; 3], "EXR gap pixel {i}");
                assert_eq!(
                    png.get_pixel((i % width) as u32, (i / width) as u32).0,
                    PNG_GAP_COLOR
                );
            }
        }
        eprintln!(
            "{width}×{height} px, {} tile pixels checked in EXR and PNG",
            covered.iter().filter(|c| **c).count()
        );

        // The PNG names its tonemap and layout in text chunks.
        let decoder = png::Decoder::new(std::io::BufReader::new(
            std::fs::File::open(&png_path).unwrap(),
        ));
        let reader = decoder.read_info().unwrap();
        let text: Vec<(String, String)> = reader
            .info()
            .utf8_text
            .iter()
            .map(|c| (c.keyword.clone(), c.get_text().unwrap()))
            .collect();
        let find = |k: &str| {
            text.iter()
                .find(|(key, _)| key == k)
                .map(|(_, v)| v.clone())
                .unwrap()
        };
        assert!(
            find("Tonemap").contains("sRGB")
                && find("Tonemap").contains(&format!("{:e}", max as f32))
        );
        assert!(find("Description").contains("`a0·ξ`"));
    }

    #[test]
    fn a_wrapped_grid_follows_ren_fig_3_and_fixes_the_other_axis() {
        let dir = scratch_dir("slices-wrapped");
        let t = table(&[2, 2, 3, 5], 1);
        // Tiles step through axis 3 (5 nodes, 2 per row: rows 0,0,1,1,2), axis 2 held at node 1.
        let layout = SliceLayout {
            x_axis: 0,
            y_axis: Some(1),
            grid: TileGrid::Wrapped {
                axis: 3,
                columns: 2,
            },
            fixed: vec![(2, 1)],
            pixels_per_node: 1,
            gap: 2,
        };
        let picture = SlicePicture::render(&t, &layout).unwrap();
        let path = dir.join("w.exr");
        picture.write_exr(&path).unwrap();
        let (w, h, exr) = read_exr(&path);
        let (gap, tile) = (2, 2);
        assert_eq!((w, h), (gap + 2 * (tile + gap), gap + 3 * (tile + gap)));
        for k in 0..5 {
            let (column, row) = (k % 2, k / 2);
            for i1 in 0..2 {
                for i0 in 0..2 {
                    let x = gap + column * (tile + gap) + i0;
                    let y = gap + (2 - row) * (tile + gap) + (1 - i1);
                    let v = value(&[i0, i1, 1, k], 0);
                    assert_eq!(exr[y * w + x], [v; 3], "k={k} node ({i0}, {i1})");
                }
            }
        }
        // The sixth place of the 2 × 3 grid (top right) is empty.
        let (x, y) = (gap + (tile + gap), gap);
        assert_eq!(exr[y * w + x], [0.0; 3]);
        assert_eq!(picture.tiles.len(), 5);
        assert_eq!(picture.tiles[4].held, vec![(2, 1), (3, 4)]);
    }

    #[test]
    fn log_tonemap_and_non_finite_values_in_the_png() {
        let dir = scratch_dir("slices-log");
        let axes = vec![Axis::uniform("x", 0.0, 1.0, 4)];
        let t = Table::new(axes, 1, vec![1000.0, 10.0, 0.0, f32::NAN]).unwrap();
        let layout = SliceLayout::default_for(&t);
        assert_eq!(layout.pixels_per_node, 4);
        let picture = SlicePicture::render(&t, &layout).unwrap();
        let path = dir.join("log.png");
        let text = picture
            .write_png(&path, PngTonemap::Log10 { decades: 4.0 })
            .unwrap();
        assert!(text.contains("log10"), "{text}");
        let png = image::open(&path).unwrap().to_rgb8();
        let at = |node: u32| png.get_pixel(1 + node * 4, 1).0;
        // 1000 is the maximum; 10 is 2 of 4 decades down: p = 0.5.
        assert_eq!(at(0), [255; 3]);
        assert_eq!(at(1), [128; 3]);
        assert_eq!(at(2), [0; 3]);
        assert_eq!(at(3), PNG_NON_FINITE_COLOR);
    }

    #[test]
    fn layouts_that_miss_or_repeat_axes_are_refused() {
        let t = table(&[2, 2, 3, 5], 1);
        let mut layout = SliceLayout::default_for(&t);
        assert!(SlicePicture::render(&t, &layout).is_ok());
        layout.grid = TileGrid::Axes {
            columns: 2,
            rows: 2,
        };
        assert!(matches!(
            SlicePicture::render(&t, &layout),
            Err(SliceError::InvalidLayout(_))
        ));
        let mut layout = SliceLayout::default_for(&t);
        layout.grid = TileGrid::Single;
        layout.fixed = vec![(2, 0), (3, 5)];
        let err = SlicePicture::render(&t, &layout).unwrap_err();
        assert!(err.to_string().contains("beyond"), "{err}");
        layout.fixed = vec![(2, 0), (3, 4)];
        layout.pixels_per_node = 100_000;
        assert!(matches!(
            SlicePicture::render(&t, &layout),
            Err(SliceError::TooLarge { .. })
        ));
    }

    #[test]
    fn the_paper_resolution_default_layout_is_a_manageable_picture() {
        let axes = [32, 32, 32, 64]
            .map(|n| Axis::uniform("x", -1.0, 1.0, n))
            .to_vec();
        let layout = SliceLayout::default_for(
            &Table::new(axes.clone(), 1, vec![0.0; 32 * 32 * 32 * 64]).unwrap(),
        );
        let shape = Shape::check(&axes, &layout).unwrap();
        eprintln!("I_M default picture: {} × {} px", shape.width, shape.height);
        assert_eq!((shape.width, shape.height), (1 + 32 * 33, 1 + 64 * 33));
    }
}
