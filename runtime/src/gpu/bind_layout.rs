//! Bind group layout entries and bind groups, the way every pass declares them: whole buffers
//! bound without dynamic offsets, unfilterable float or depth textures read with `textureLoad`
//! (the passes never sample with filtering), and bindings numbered in declaration order.
//! One home for this boilerplate so that a pass's layout reads as the list of what it binds.

/// A uniform buffer at `binding`.
pub fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(binding, visibility, wgpu::BufferBindingType::Uniform)
}

/// A storage buffer at `binding`; `read_only` unless the shader writes or atomically updates it.
pub fn storage_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    read_only: bool,
) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(
        binding,
        visibility,
        wgpu::BufferBindingType::Storage { read_only },
    )
}

fn buffer_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A texture at `binding`, single-sampled.
pub fn texture_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    sample_type: wgpu::TextureSampleType,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension,
            multisampled: false,
        },
        count: None,
    }
}

/// A 2D float texture read with `textureLoad` (unfilterable: `Rgba32Float` is not filterable
/// on every adapter).
pub fn float_texture_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    texture_entry(
        binding,
        visibility,
        wgpu::TextureSampleType::Float { filterable: false },
        wgpu::TextureViewDimension::D2,
    )
}

/// A 2D float texture array read with `textureLoad` (unfilterable, as [`float_texture_entry`]).
pub fn float_array_texture_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    texture_entry(
        binding,
        visibility,
        wgpu::TextureSampleType::Float { filterable: false },
        wgpu::TextureViewDimension::D2Array,
    )
}

/// A 2D depth texture read with `textureLoad`.
pub fn depth_texture_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    texture_entry(
        binding,
        visibility,
        wgpu::TextureSampleType::Depth,
        wgpu::TextureViewDimension::D2,
    )
}

/// A 2D depth texture array read with `textureLoad`.
pub fn depth_array_texture_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    texture_entry(
        binding,
        visibility,
        wgpu::TextureSampleType::Depth,
        wgpu::TextureViewDimension::D2Array,
    )
}

/// A 2D storage texture of `format` at `binding`, written (never read) by the shader.
pub fn storage_texture_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    format: wgpu::TextureFormat,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        count: None,
    }
}

/// A bind group of `resources` at bindings 0, 1, 2, … in order.
pub fn bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: &[wgpu::BindingResource<'_>],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = resources
        .iter()
        .enumerate()
        .map(|(binding, resource)| wgpu::BindGroupEntry {
            binding: binding as u32,
            resource: resource.clone(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// A pipeline layout of bind groups `groups` (None: a group the pipeline does not use).
pub fn pipeline_layout(
    device: &wgpu::Device,
    label: &str,
    groups: &[Option<&wgpu::BindGroupLayout>],
) -> wgpu::PipelineLayout {
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: groups,
        immediate_size: 0,
    })
}
