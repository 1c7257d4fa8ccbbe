//! What the second core buys the full app: Maslova's frame experiment (the whole Bevy app
//! without a window, `ClothPlugin`, mesh write-back) at 65,536 mass-spring particles, with
//! the cloth's kernels on one thread and on the compute pool, alternately, twice.
//!
//! `cargo run -p bevy_cloth_lab --example app_cores`
fn main() {
    for round in 0..2 {
        for parallel in [false, true] {
            bevy_cloth::solver::set_parallel(parallel);
            match bevy_cloth_lab::fps::app_frame("1", 65_536, 5, 20) {
                Ok(row) => println!(
                    "round {round}, {} thread(s): {} ms per frame",
                    bevy_cloth::solver::threads(),
                    row.ms_per_frame
                        .map_or("failed".to_string(), |ms| format!("{ms:.1}"))
                ),
                Err(e) => println!("round {round}: {e}"),
            }
        }
    }
}
