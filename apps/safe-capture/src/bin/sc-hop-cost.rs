//! `sc-hop-cost`: what one hop of the partition costs on this machine (a sample and
//! its wake-up to a second process and back). See `sc_ground::hop_cost`.
//!
//! ```sh
//! target/release/sc-hop-cost --n 300 --period-us 100000 --cpus 1,1 --fifo 50 --cpu-wakeup-latency-us 0
//! ```

use sc_ground::error::BenchError;
use sc_ground::hop_cost::{HopCostOptions, echo_from_env, measure};

/// `sc-hop-cost`: measures and prints the round trips, or (with `--echo`, on the
/// child it starts) answers them. Exit code 2 on bad arguments, 1 on failure.
fn main() -> std::process::ExitCode {
    use std::process::ExitCode;
    let args: Vec<String> = std::env::args().skip(1).collect();
    let o = match HopCostOptions::parse(&args) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("sc-hop-cost: {e}");
            return ExitCode::from(2);
        }
    };
    let r = if o.echo {
        echo_from_env(&o)
    } else {
        std::env::current_exe()
            .map_err(|e| BenchError::Data(format!("cannot find this executable: {e}")))
            .and_then(|exe| measure(&o, &exe, &args))
            .map(|rt| println!("{rt}, period {:?}", o.period))
    };
    match r {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("sc-hop-cost: {e}");
            ExitCode::FAILURE
        }
    }
}
