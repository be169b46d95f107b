//! Fits one map and prints every round: `fit_one MAP [initial] [target] [lambda_max]`.
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let map =
        strandlight_precompute::envmap_io::load(std::path::Path::new(&a[1]), Default::default())
            .unwrap()
            .map;
    let mut o = strandlight_precompute::FitOptions::default();
    if let Some(v) = a.get(2) {
        o.initial_lobes = v.parse().unwrap();
    }
    if let Some(v) = a.get(3) {
        o.target_relative_mse = v.parse().unwrap();
    }
    if let Some(v) = a.get(4) {
        o.lambda_max = v.parse().unwrap();
    }
    if let Some(v) = a.get(5) {
        o.iterations_per_round = v.parse().unwrap();
    }
    let t = std::time::Instant::now();
    let r = strandlight_precompute::fit(&map, &o, &mut |r| {
        eprintln!(
            "{:>3} lobes  rel. MSE {:.5}  {:>5} evals  {:.2}s",
            r.lobes,
            r.relative_mse,
            r.evaluations,
            t.elapsed().as_secs_f64()
        )
    })
    .unwrap();
    eprintln!(
        "{} lobes, objective {:.5}, {:.2}s",
        r.lobes.len(),
        r.objective_relative_mse,
        t.elapsed().as_secs_f64()
    );
}
