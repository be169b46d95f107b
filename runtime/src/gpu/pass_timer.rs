//! GPU time per pass from timestamp queries, on adapters that have them.
//!
//! Wall-clock time around "submit and wait" also counts the CPU work that records the passes,
//! uploads and the driver's submission; on a real GPU that can dwarf the GPU's own time. Each
//! render and compute pass asks the context for its timestamp writes
//! ([`GpuContext::render_timestamps`], [`GpuContext::compute_timestamps`]); while a thread has a
//! section open they land in one query set, and closing the section sums end − begin over every
//! pass it recorded.

use std::sync::Mutex;
use std::thread::ThreadId;

use super::GpuContext;
use super::readback::read_timestamps;

/// Query slots per section: two per pass, so up to 2048 passes between `begin` and `end`.
const CAPACITY: u32 = wgpu::QUERY_SET_MAX_QUERIES;

pub struct PassTimer {
    queries: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    nanoseconds_per_tick: f64,
    section: Mutex<Section>,
}

#[derive(Default)]
struct Section {
    /// The thread whose passes are being timed; passes on other threads go untimed, so two
    /// threads sharing a device never mix their sums.
    owner: Option<ThreadId>,
    next_query: u32,
    overflowed: bool,
}

impl PassTimer {
    /// A timer when the device was created with [`wgpu::Features::TIMESTAMP_QUERY`].
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Option<Self> {
        if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            return None;
        }
        let queries = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: CAPACITY,
        });
        let resolved = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pass timestamps resolved"),
            size: u64::from(CAPACITY) * u64::from(wgpu::QUERY_SIZE),
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        Some(Self {
            queries,
            resolved,
            nanoseconds_per_tick: f64::from(queue.get_timestamp_period()),
            section: Mutex::new(Section::default()),
        })
    }

    /// Starts timing this thread's passes. False when another section is open (on another
    /// thread, or an enclosing one on this thread): the caller then reports no GPU time.
    pub fn begin(&self) -> bool {
        let mut s = self.lock();
        if s.owner.is_some() {
            return false;
        }
        *s = Section {
            owner: Some(std::thread::current().id()),
            ..Section::default()
        };
        true
    }

    /// Closes the section opened by a successful [`begin`](Self::begin): the GPU milliseconds
    /// of its passes, or `None` when it recorded no pass, ran out of query slots, or the
    /// results could not be read. Call after the section's work has been submitted.
    pub fn end(&self, gpu: &GpuContext) -> Option<f64> {
        let (queries, overflowed) = {
            let mut s = self.lock();
            let out = (s.next_query, s.overflowed);
            *s = Section::default();
            out
        };
        if queries == 0 || overflowed {
            return None;
        }
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        encoder.resolve_query_set(&self.queries, 0..queries, &self.resolved, 0);
        gpu.queue.submit([encoder.finish()]);
        let bytes = read_timestamps(gpu, &self.resolved).ok()?;
        let ticks: Vec<u64> = bytes
            .chunks_exact(8)
            .take(queries as usize)
            .map(|b| u64::from_le_bytes(b.try_into().expect("8-byte chunk")))
            .collect();
        Some(self.pass_ticks_to_ms(&ticks))
    }

    /// Sum of end − begin over (begin, end) pairs, in milliseconds. A pair that runs
    /// backwards (a wrapped or reset counter) counts as zero rather than as ~2⁶⁴ ticks.
    fn pass_ticks_to_ms(&self, ticks: &[u64]) -> f64 {
        let total: u64 = ticks
            .chunks_exact(2)
            .map(|p| p[1].saturating_sub(p[0]))
            .sum();
        total as f64 * self.nanoseconds_per_tick * 1e-6
    }

    /// The next (begin, end) slots when the calling thread owns the open section.
    fn next_pair(&self) -> Option<(u32, u32)> {
        let mut s = self.lock();
        if s.owner != Some(std::thread::current().id()) {
            return None;
        }
        if s.next_query + 2 > CAPACITY {
            s.overflowed = true;
            return None;
        }
        let begin = s.next_query;
        s.next_query += 2;
        Some((begin, begin + 1))
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Section> {
        // A panic while holding the lock leaves plain counters behind; they are still usable.
        self.section.lock().unwrap_or_else(|p| p.into_inner())
    }
}

impl GpuContext {
    /// Timestamp writes for a render pass: `Some` only inside an open timing section.
    pub fn render_timestamps(&self) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let timer = self.pass_timer.as_ref()?;
        let (begin, end) = timer.next_pair()?;
        Some(wgpu::RenderPassTimestampWrites {
            query_set: &timer.queries,
            beginning_of_pass_write_index: Some(begin),
            end_of_pass_write_index: Some(end),
        })
    }

    /// Timestamp writes for a compute pass: `Some` only inside an open timing section.
    pub fn compute_timestamps(&self) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let timer = self.pass_timer.as_ref()?;
        let (begin, end) = timer.next_pair()?;
        Some(wgpu::ComputePassTimestampWrites {
            query_set: &timer.queries,
            beginning_of_pass_write_index: Some(begin),
            end_of_pass_write_index: Some(end),
        })
    }

    /// Runs `work` (which submits passes), waits for the GPU, and returns its result with the
    /// wall-clock milliseconds and, where the adapter has timestamp queries, the GPU
    /// milliseconds of the passes it recorded. On a host's device ([`GpuContext::waits_to_time`]
    /// false) it does not wait: the milliseconds are the encoding's alone.
    pub fn time_passes<T>(&self, work: impl FnOnce() -> T) -> (T, f64, Option<f64>) {
        let mut open = CloseOnUnwind(self.pass_timer.as_ref().filter(|t| t.begin()));
        // std's clock panics in a browser; web-time is std's elsewhere.
        let start = web_time::Instant::now();
        let out = work();
        if !self.waits_to_time {
            return (out, start.elapsed().as_secs_f64() * 1e3, None);
        }
        self.wait_idle();
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        let gpu_ms = open.0.take().and_then(|t| t.end(self));
        (out, wall_ms, gpu_ms)
    }
}

/// Closes a section whose work panicked: left open, it would belong to that thread forever and
/// every later section on a shared device would go untimed.
struct CloseOnUnwind<'a>(Option<&'a PassTimer>);

impl Drop for CloseOnUnwind<'_> {
    fn drop(&mut self) {
        if let Some(timer) = self.0 {
            *timer.lock() = Section::default();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Who gets query slots: only the thread that opened the section, only while it is open.
    #[test]
    fn only_the_thread_with_the_open_section_gets_query_slots() {
        let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
        let Some(timer) = gpu.pass_timer.as_ref() else {
            eprintln!("skipped: {} has no timestamp queries", gpu.report);
            return;
        };
        assert!(gpu.render_timestamps().is_none(), "slots outside a section");
        assert!(timer.begin());
        assert!(
            !timer.begin(),
            "a nested section must not restart the open one"
        );
        assert!(gpu.compute_timestamps().is_some());
        std::thread::scope(|s| {
            s.spawn(|| {
                assert!(!timer.begin(), "a second thread opened a section");
                assert!(
                    gpu.render_timestamps().is_none(),
                    "another thread got slots"
                );
            });
        });
        // One pair was handed out but no pass wrote it: whatever the resolve reads, the sum
        // stays finite and non-negative.
        let ms = timer.end(&gpu).expect("one pair recorded");
        assert!(ms.is_finite() && ms >= 0.0, "{ms}");
        assert!(
            gpu.render_timestamps().is_none(),
            "slots after the section closed"
        );
        assert!(
            timer.end(&gpu).is_none(),
            "an empty section has no GPU time"
        );

        // A panic inside a timed section leaves it closed for the next one.
        let panicked = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            gpu.time_passes(|| panic!("injected"))
        }));
        assert!(panicked.is_err());
        assert!(timer.begin(), "the panicked section was left open");
        assert!(timer.end(&gpu).is_none());
    }
}
