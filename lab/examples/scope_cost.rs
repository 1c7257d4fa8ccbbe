//! What one fork-join on the compute task pool costs here: 10,000 scopes of two empty
//! tasks each, back to back and with 0.1 ms of work between them (the pool's threads
//! then fall asleep between scopes, as they do between a cloth's kernels).
//!
//! `cargo run -p bevy_cloth_lab --example scope_cost`
use std::time::{Duration, Instant};

fn main() {
    let pool = bevy_cloth::lab::task_pool();
    println!("pool threads: {}", pool.thread_num());
    for gap in [Duration::ZERO, Duration::from_micros(100)] {
        let mut total = Duration::ZERO;
        for _ in 0..10_000 {
            let spin = Instant::now();
            while spin.elapsed() < gap {}
            let start = Instant::now();
            pool.scope(|scope| {
                for _ in 0..2 {
                    scope.spawn(async {});
                }
            });
            total += start.elapsed();
        }
        println!(
            "{:>4} us of work between scopes: {:.1} us per scope",
            gap.as_micros(),
            total.as_secs_f64() * 1e6 / 10_000.0
        );
    }
}
