//! Monte Carlo campaigns: dispersions, parallel runs, shards, merge, report.
