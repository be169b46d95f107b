//! What the page's tests share (tests/web_page.rs, tests/frame_replay.rs): a bundle's files as
//! the page fetches them, the page's own session stepped natively to convergence, and the
//! block means and totals the browser's frames are compared by.

use std::path::Path;
use strandlight_runtime::gpu::GpuContext;
use strandlight_scene::image_metrics::Image;
use strandlight_web::session::{BundleFiles, Session};

/// Mean of `k`×`k` blocks.
pub fn blocks(image: &Image, k: u32) -> Image {
    let (w, h) = (image.width / k, image.height / k);
    let pixels = (0..h)
        .flat_map(|by| (0..w).map(move |bx| (bx, by)))
        .map(|(bx, by)| {
            let mut sum = [0.0f32; 4];
            for y in by * k..(by + 1) * k {
                for x in bx * k..(bx + 1) * k {
                    let p = image.pixels[(y * image.width + x) as usize];
                    (0..4).for_each(|c| sum[c] += p[c] / (k * k) as f32);
                }
            }
            sum
        })
        .collect();
    Image {
        width: w,
        height: h,
        pixels,
    }
}

pub fn total(image: &Image) -> f64 {
    image
        .pixels
        .iter()
        .map(|p| (p[0] + p[1] + p[2]) as f64)
        .sum()
}

/// The bundle's files as the page fetches them.
pub fn bundle_files(bundle: &Path) -> BundleFiles {
    let mut files = BundleFiles::new();
    for entry in std::fs::read_dir(bundle)
        .unwrap()
        .chain(std::fs::read_dir(bundle.join("tables")).unwrap())
    {
        let path = entry.unwrap().path();
        if path.is_file() {
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            files.insert(name, std::fs::read(&path).unwrap());
        }
    }
    files
}

/// Every step of the plan, the forward-scattering march read back when the session asks (as
/// the page's ticks do, but waiting for the GPU).
pub fn step_to_the_end(session: &mut Session) {
    let mut steps = 0;
    while session.refining() {
        session.step().unwrap();
        if let Some((id, buffers)) = session.march_readback() {
            let values = buffers.iter().map(|b| map_blocking(session, b)).collect();
            session.march_done(id, values).unwrap();
        }
        steps += 1;
        assert!(steps < 1000, "the session does not advance");
    }
}

pub fn map_blocking(session: &Session, buffer: &wgpu::Buffer) -> Vec<[f32; 4]> {
    let slice = buffer.slice(..);
    slice.map_async(wgpu::MapMode::Read, |r| r.unwrap());
    session.gpu().wait_idle();
    let values = bytemuck::pod_collect_to_vec(&slice.get_mapped_range().unwrap());
    buffer.unmap();
    values
}

/// The page's steps run natively (lavapipe): every step encoded, the last readback mapped.
pub fn native_session(bundle: &Path) -> Image {
    let session = Session::new(GpuContext::new_headless().unwrap(), bundle_files(bundle)).unwrap();
    converge(session)
}

pub fn converge(mut session: Session) -> Image {
    step_to_the_end(&mut session);
    let readback = session.readback().expect("a picture to read back");
    let sums = map_blocking(&session, &readback.buffer);
    session.readback_done(&readback, &sums);
    let [width, height] = session.settings.size;
    Image {
        width,
        height,
        pixels: session
            .converged
            .take()
            .expect("converged after the last step"),
    }
}
