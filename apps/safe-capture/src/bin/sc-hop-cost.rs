//! `sc-hop-cost`: what one hop of the partition costs on this machine (a sample and
//! its wake-up to a second process and back). See `sc_ground::hop_cost`.
//!
//! ```sh
//! target/release/sc-hop-cost --n 300 --period-us 100000 --cpus 1,1 --fifo 50 --cpu-wakeup-latency-us 0
//! ```
fn main() -> std::process::ExitCode {
    sc_ground::hop_cost::main()
}
