//! How strandlight measures itself: the SRBF / reference / median-cut comparison of Ren 2010
//! §8, the path-traced ground truth (Mitsuba 3), HDR-FLIP, the error decomposition, and `bench`
//! with its plots and report.
//!
//! It sits above `strandlight-scene` and renders through the same frame function the product
//! uses, so what it measures is what a user gets; nothing below it depends on it.

pub mod baseline;
pub mod bench;
pub mod bench_plots;
pub mod bench_report;
pub mod compare;
mod compare_settings_legacy;
pub mod compare_table;
pub mod equal_time;
pub mod error_decomposition;
pub mod error_metric;
pub mod ground_truth;
pub mod hdr_flip;
pub mod reference_cache;
pub mod summary;
