fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = std::path::Path::new(&args[1]);
    let t = std::time::Instant::now();
    let loaded = strandlight_precompute::envmap_io::load(path, Default::default()).unwrap();
    eprintln!("load {:.2}s", t.elapsed().as_secs_f64());
    let mut opts = strandlight_precompute::FitOptions::default();
    if args.len() > 2 { opts.target_relative_mse = args[2].parse().unwrap(); opts.initial_lobes = 16; }
    if args.len() > 3 { opts.lambda_max = args[3].parse().unwrap(); }
    let t = std::time::Instant::now();
    let fit = strandlight_precompute::fit(&loaded.map, &opts, &mut |r| eprintln!("{:?} {:.2}s", r, t.elapsed().as_secs_f64())).unwrap();
    eprintln!("fit {:.2}s, {} lobes, E={}", t.elapsed().as_secs_f64(), fit.lobes.len(), fit.objective_relative_mse);
    let d = strandlight_precompute::srbf_objective::relative_mse_by_pixels(&fit.grid_map, &fit.lobes);
    let f = strandlight_precompute::srbf_objective::relative_mse_by_pixels(&loaded.map, &fit.lobes);
    eprintln!("direct grid {d}, full {f}, {:.2}s", t.elapsed().as_secs_f64());
}
