//! Heads from glTF 2.0 files (`.glb`, or `.gltf` with embedded or external buffers) through the
//! `gltf` crate: every triangle primitive of every mesh in the default scene (else the first),
//! through its node's transform and its ancestors', in strandlight's world: glTF's Y up and
//! metres, taken to centimetres (the unit of the USD and Alembic readers' world). Normals are
//! the file's where a primitive has them, else computed from its faces; a node that mirrors
//! (negative determinant) turns its faces, as the glTF specification asks. Points, lines,
//! strips and fans are not surfaces a head is made of here, and are skipped; materials,
//! textures, skins and morph targets are not read.

use anyhow::{Context, bail};
use glam::{Mat3, Mat4, Vec3};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use strandlight_runtime::hair::guard::panic_message;
use strandlight_runtime::head::TriangleMesh;

/// glTF's metres in strandlight's centimetres.
const CENTIMETRES_PER_METRE: f32 = 100.0;

/// Nodes deeper than this are refused: a file whose nodes form a cycle (which validation does
/// not catch) would otherwise recurse until the stack overflows.
const MAX_NODE_DEPTH: usize = 128;

/// Node visits beyond this are refused: nodes that share children (which validation does not
/// catch either) make the walk exponential in the depth.
const MAX_NODE_VISITS: usize = 65_536;

/// The head mesh in the glTF file at `path`.
pub fn load_gltf(path: &Path) -> anyhow::Result<TriangleMesh> {
    let bytes =
        std::fs::read(path).with_context(|| format!("cannot read the head {}", path.display()))?;
    parse_gltf(&bytes, path)
}

/// The head mesh in `bytes`, the glTF file at `path` (which names it in errors, and beside
/// which a `.gltf`'s external buffers are looked for).
pub fn parse_gltf(bytes: &[u8], path: &Path) -> anyhow::Result<TriangleMesh> {
    // The crate's accessor reads index into the buffers as the file says; a damaged file must
    // give a message naming it, not end the viewer.
    catch_unwind(AssertUnwindSafe(|| read_gltf(path, bytes))).unwrap_or_else(|panic| {
        bail!(
            "{}: the glTF reader failed on this file ({})",
            path.display(),
            panic_message(&*panic)
        )
    })
}

fn read_gltf(path: &Path, bytes: &[u8]) -> anyhow::Result<TriangleMesh> {
    let gltf = gltf::Gltf::from_slice(bytes)
        .with_context(|| format!("{}: not a readable glTF 2.0 file", path.display()))?;
    check_buffer_files(&gltf.document, path)?;
    let buffers = gltf::import_buffers(&gltf.document, path.parent(), gltf.blob.clone())
        .with_context(|| format!("{}: cannot load the file's buffers", path.display()))?;
    let scene = gltf
        .document
        .default_scene()
        .or_else(|| gltf.document.scenes().next())
        .with_context(|| format!("{}: the file has no scene", path.display()))?;
    let mut head = HeadParts::default();
    for node in scene.nodes() {
        head.add_node(&node, Mat4::IDENTITY, &buffers, 0)
            .with_context(|| format!("{}", path.display()))?;
    }
    if head.indices.is_empty() {
        bail!(
            "{}: the scene has no triangles (a head needs a mesh with a triangle primitive)",
            path.display()
        );
    }
    Ok(TriangleMesh::new(
        head.positions,
        head.normals,
        head.indices,
    ))
}

/// Refuses a buffer whose URI names something other than a regular file: the crate reads the
/// whole of what a URI names, and `/dev/zero` or a FIFO would never end.
fn check_buffer_files(document: &gltf::Document, path: &Path) -> anyhow::Result<()> {
    let base = path.parent().unwrap_or(Path::new(""));
    for buffer in document.buffers() {
        let gltf::buffer::Source::Uri(uri) = buffer.source() else {
            continue;
        };
        let named = if uri.starts_with("data:") {
            continue;
        } else if let Some(file) = uri
            .strip_prefix("file://")
            .or_else(|| uri.strip_prefix("file:"))
        {
            std::path::PathBuf::from(file)
        } else if uri.contains(':') {
            continue; // a scheme the crate refuses itself
        } else {
            base.join(percent_decoded(uri))
        };
        if !std::fs::metadata(&named).is_ok_and(|m| m.is_file()) {
            bail!(
                "{}: buffer {} names {}, which is not a file",
                path.display(),
                buffer.index(),
                named.display()
            );
        }
    }
    Ok(())
}

/// A relative URI's path as the crate reads it: %XX escapes decoded (invalid ones kept).
fn percent_decoded(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes
            .get(i + 1..i + 3)
            .and_then(|h| u8::from_str_radix(std::str::from_utf8(h).ok()?, 16).ok());
        match (bytes[i], hex) {
            (b'%', Some(byte)) => {
                out.push(byte);
                i += 3;
            }
            (b, _) => {
                out.push(b);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The triangles gathered so far, in strandlight's world.
#[derive(Default)]
struct HeadParts {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    indices: Vec<u32>,
    nodes_visited: usize,
}

impl HeadParts {
    fn add_node(
        &mut self,
        node: &gltf::Node,
        parent: Mat4,
        buffers: &[gltf::buffer::Data],
        depth: usize,
    ) -> anyhow::Result<()> {
        if depth > MAX_NODE_DEPTH {
            bail!("nodes nested deeper than {MAX_NODE_DEPTH} (a cycle?)");
        }
        self.nodes_visited += 1;
        if self.nodes_visited > MAX_NODE_VISITS {
            bail!("more than {MAX_NODE_VISITS} node visits (nodes shared as children?)");
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let to_world = parent * local;
        if !to_world.is_finite() {
            bail!("node {}: its transform is not finite", node_name(node));
        }
        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                if primitive.mode() == gltf::mesh::Mode::Triangles {
                    self.add_primitive(&primitive, to_world, buffers)
                        .with_context(|| {
                            format!(
                                "node {}, mesh {}, primitive {}",
                                node_name(node),
                                mesh.name().unwrap_or("(unnamed)"),
                                primitive.index()
                            )
                        })?;
                }
            }
        }
        for child in node.children() {
            self.add_node(&child, to_world, buffers, depth + 1)?;
        }
        Ok(())
    }

    fn add_primitive(
        &mut self,
        primitive: &gltf::Primitive,
        node_to_world: Mat4,
        buffers: &[gltf::buffer::Data],
    ) -> anyhow::Result<()> {
        let to_world = Mat4::from_scale(Vec3::splat(CENTIMETRES_PER_METRE)) * node_to_world;
        let reader = primitive.reader(|buffer| buffers.get(buffer.index()).map(|d| &d.0[..]));
        let positions: Vec<Vec3> = reader
            .read_positions()
            .context("no POSITION attribute")?
            .map(|p| to_world.transform_point3(Vec3::from(p)))
            .collect();
        if let Some(p) = positions.iter().find(|p| !p.is_finite()) {
            bail!("a position is not finite ({p})");
        }
        let mut indices: Vec<u32> = match reader.read_indices() {
            Some(indices) => indices.into_u32().collect(),
            None => (0..positions.len() as u32).collect(),
        };
        if !indices.len().is_multiple_of(3) {
            bail!("{} indices do not make whole triangles", indices.len());
        }
        if let Some(i) = indices.iter().find(|&&i| i as usize >= positions.len()) {
            bail!("an index names vertex {i} of {}", positions.len());
        }
        if to_world.determinant() < 0.0 {
            for t in indices.chunks_exact_mut(3) {
                t.swap(1, 2);
            }
        }
        let normals: Vec<Vec3> = match reader.read_normals() {
            Some(normals) => {
                let normal_to_world = Mat3::from_mat4(to_world).inverse().transpose();
                normals
                    .map(|n| (normal_to_world * Vec3::from(n)).normalize_or(Vec3::Y))
                    .collect()
            }
            None => Vec::new(),
        };
        let part = if normals.len() == positions.len() {
            TriangleMesh::new(positions, normals, indices)
        } else {
            TriangleMesh::with_computed_normals(positions, indices)
        };
        let base = self.positions.len() as u32;
        self.indices.extend(part.indices.iter().map(|i| base + i));
        self.positions.extend(part.positions);
        self.normals.extend(part.normals);
        Ok(())
    }
}

fn node_name(node: &gltf::Node) -> String {
    match node.name() {
        Some(name) => format!("{name:?}"),
        None => format!("#{}", node.index()),
    }
}
