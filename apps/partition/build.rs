// The git commit of the build, the same way as `safe-capture` (see that file): the
// recorder puts it into the partition's summary.json.
include!("../safe-capture/build.rs");
