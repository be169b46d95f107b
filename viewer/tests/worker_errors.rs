//! The render thread without a window: a bad hair file (as dropped on the window) comes back as
//! an error naming the file, the thread keeps working, and the next good request is drawn as a
//! preview and then converged, with the image the size asked for.

use std::time::{Duration, Instant};
use strandlight_scene::env_frame::shared_gpu;
use strandlight_scene::frame_settings::{FrameSettings, Lighting, PointLighting};
use strandlight_viewer::frame::Stage;
use strandlight_viewer::worker::Worker;

fn wait_for(worker: &Worker, what: &str, done: impl Fn(&Worker) -> bool) {
    let start = Instant::now();
    while !done(worker) {
        assert!(
            start.elapsed() < Duration::from_secs(300),
            "timed out waiting for {what}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_bad_file_is_an_error_naming_it_and_the_next_request_still_renders() {
    let dir = std::env::temp_dir().join(format!("strandlight-worker-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("dropped.hair");
    std::fs::write(&bad, b"HAIR but not really a hair file").unwrap();
    // The image stays on the GPU (no read back), as for a window on the renderer's device.
    let worker = Worker::spawn(dir.join("cache"), false, false, Box::new(|| {}));
    let mut settings = FrameSettings::new(Lighting::Lights(PointLighting::default()), [48, 32]);
    settings.hair = Some(bad.clone());
    worker.submit(1, settings.clone());
    wait_for(&worker, "the error", |w| w.status().error.is_some());
    let (job, message) = worker.status().error.clone().unwrap();
    assert_eq!(job, 1);
    assert!(message.contains("dropped.hair"), "{message}");
    assert!(worker.status().shown.is_none());

    settings.hair = None;
    worker.submit(2, settings);
    wait_for(&worker, "a converged frame", |w| {
        w.status()
            .shown
            .as_ref()
            .is_some_and(|s| s.job == 2 && s.stage == Stage::Converged)
    });
    let status = worker.status().clone();
    let shown = status.shown.unwrap();
    assert_eq!(shown.image.size, [48, 32]);
    assert!(shown.image.read_back.is_none(), "kept on the GPU");
    let image = shown.image.read(shared_gpu().unwrap()).unwrap();
    assert_eq!((image.width, image.height), (48, 32));
    assert!(image.pixels.iter().any(|p| p[3] > 0.0), "hair drawn");
    assert!(status.preview_seconds.is_some(), "a preview came first");
    assert!(status.error.is_none(), "the success cleared the error");
    drop(worker);
    std::fs::remove_dir_all(&dir).unwrap();
}
