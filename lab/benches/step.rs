//! Regression benches: one 16 ms step of each model of Sladović's (2014) fig. 23 on the
//! timing table's curtain (top row pinned, gravity, the default wind) at 4,096 and
//! 65,536 particles. `cargo bench --bench step`; the tables and charts are made by
//! `cargo run --bin cloth -- bench`.

use criterion::{Criterion, criterion_group, criterion_main};

use bevy_cloth::params::Environment;
use bevy_cloth_lab::{SEED_MODELS, bench_cloth};

fn step(c: &mut Criterion) {
    let env = Environment::default();
    for count in [4_096, 65_536] {
        let mut group = c.benchmark_group(format!("step_{count}"));
        if count > 4_096 {
            group.sample_size(10);
        }
        for model in SEED_MODELS {
            let mut cloth = bench_cloth(model, count).expect("a fig. 23 model");
            // Past the first steps, whose substep count and caches settle.
            for _ in 0..3 {
                cloth.step(0.016, &env);
            }
            group.bench_function(model, |b| b.iter(|| cloth.step(0.016, &env)));
        }
        group.finish();
    }
}

criterion_group!(benches, step);
criterion_main!(benches);
