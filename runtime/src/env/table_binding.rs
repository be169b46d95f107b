//! Group 2 of the view shading pass: a light kind's single-scattering table and the
//! multiple-scattering table on the GPU (`table_lookup.wgsl` reads them), and the cache that
//! keeps them across frames.

use std::sync::{Arc, Mutex};

use strandlight_tables::table::{AxisGpu, Table};

use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{bind_group, storage_entry, uniform_entry};
use crate::gpu::buffer::init_buffer;

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct TableLayoutUniform {
    axes: [AxisGpu; 4],
    strides: [u32; 4],
}

/// A four-axis RGB table's uniform: axes and element strides (row-major, channels innermost).
fn table_layout(table: &Table) -> TableLayoutUniform {
    let axes = table.gpu_axes();
    let shape = table.shape();
    let c = table.channels();
    TableLayoutUniform {
        axes: [axes[0], axes[1], axes[2], axes[3]],
        strides: [
            (shape[1] * shape[2] * shape[3] * c) as u32,
            (shape[2] * shape[3] * c) as u32,
            (shape[3] * c) as u32,
            c as u32,
        ],
    }
}

/// Group 2: the single-scattering table (the SRBF convolution table, or the direct table for
/// directional lights) and the multiple-scattering table (a 1-element placeholder where absent).
/// Built once per light kind per frame.
pub struct TableBinding {
    pub group: wgpu::BindGroup,
    pub bytes: u64,
}

impl TableBinding {
    /// Tables must have 4 axes and 3 channels (checked by the caller).
    pub fn new(
        gpu: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        single: &Table,
        multiple: Option<&Table>,
    ) -> Self {
        let device = &gpu.device;
        let storage = wgpu::BufferUsages::STORAGE;
        let uniform = wgpu::BufferUsages::UNIFORM;
        let single_layout = init_buffer(
            device,
            "env single layout",
            bytemuck::bytes_of(&table_layout(single)),
            uniform,
        );
        let single_values = init_buffer(device, "env single table", single.as_bytes(), storage);
        let multiple_table = multiple.unwrap_or(single);
        let multiple_layout = init_buffer(
            device,
            "env multiple layout",
            bytemuck::bytes_of(&table_layout(multiple_table)),
            uniform,
        );
        let multiple_values = match multiple {
            Some(t) => init_buffer(device, "env multiple table", t.as_bytes(), storage),
            None => init_buffer(device, "env multiple table", &[0u8; 16], storage),
        };
        let buffers = [
            &single_layout,
            &single_values,
            &multiple_layout,
            &multiple_values,
        ];
        let resources = buffers.map(|b| b.as_entire_binding());
        Self {
            group: bind_group(device, "env tables", layout, &resources),
            bytes: buffers.iter().map(|b| b.size()).sum(),
        }
    }
}

/// Group 2's layout: each table's layout uniform and values.
pub fn table_bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let fragment = wgpu::ShaderStages::FRAGMENT;
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("env tables"),
        entries: &[
            uniform_entry(0, fragment),
            storage_entry(1, fragment, true),
            uniform_entry(2, fragment),
            storage_entry(3, fragment, true),
        ],
    })
}

/// Tables uploaded and bound: the same tables are the same allocations (`Arc::ptr_eq`), which
/// the cache's own references keep from being reused by other tables.
struct CachedTables {
    single: Arc<Table>,
    multiple: Option<Arc<Table>>,
    binding: Arc<TableBinding>,
}

/// A frame binds at most two pairs of tables (SRBF and directional lights).
const CACHED_TABLE_BINDINGS: usize = 2;

/// The last frames' tables on the GPU, kept while frames bind the same tables (a progressive
/// frame's steps, a viewer's frames): their upload was most of a step's CPU time in a web page
/// (tens of MB a step).
#[derive(Default)]
pub(super) struct TableCache(Mutex<Vec<CachedTables>>);

impl TableCache {
    /// `single` bound with `multiple` (see [`TableBinding`]) against `layout`, uploaded unless a
    /// recent frame bound the same tables.
    pub(super) fn binding(
        &self,
        gpu: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        single: &Arc<Table>,
        multiple: Option<&Arc<Table>>,
    ) -> Arc<TableBinding> {
        let mut cache = self.0.lock().expect("table cache lock");
        let same = |c: &CachedTables| {
            Arc::ptr_eq(&c.single, single)
                && match (&c.multiple, multiple) {
                    (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                    (None, None) => true,
                    _ => false,
                }
        };
        if let Some(cached) = cache.iter().find(|c| same(c)) {
            return cached.binding.clone();
        }
        let binding = Arc::new(TableBinding::new(
            gpu,
            layout,
            single,
            multiple.map(|m| &**m),
        ));
        if cache.len() == CACHED_TABLE_BINDINGS {
            cache.remove(0);
        }
        cache.push(CachedTables {
            single: single.clone(),
            multiple: multiple.cloned(),
            binding: binding.clone(),
        });
        binding
    }
}

#[cfg(test)]
mod wgsl_layout {
    use super::*;
    use crate::shader_layout::{assert_same_layout, rust_layout};
    use crate::shaders::Wgsl;
    use strandlight_tables::table::AxisGpu;

    #[test]
    fn uploaded_structs_are_laid_out_as_the_wgsl_reads_them() {
        assert_same_layout(
            &Wgsl {
                file: "table_lookup.wgsl",
                source: include_str!("table_lookup.wgsl"),
            },
            None,
            "TableLayout",
            &rust_layout!(TableLayoutUniform { axes, strides }),
        );
        assert_same_layout(
            &Wgsl {
                file: "table_axis.wgsl",
                source: include_str!("../passes/table_axis.wgsl"),
            },
            None,
            "TableAxis",
            &rust_layout!(AxisGpu {
                min,
                inv_range,
                last_index,
                inv_exponent,
                warp
            }),
        );
    }
}
