//! Converts the SVG figures of existing output folders, e.g. a run written before
//! `--figure-format` existed:
//!
//! `cargo run --release -p sc-plots --example export_figures -- png,pdf out/run/figures`

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [formats, dirs @ ..] = args.as_slice() else {
        eprintln!("usage: export_figures FORMATS DIR... (FORMATS: e.g. png,pdf)");
        std::process::exit(2);
    };
    let formats = match sc_plots::FigureFormats::parse(formats) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("export_figures: {e}");
            std::process::exit(2);
        }
    };
    for dir in dirs {
        match sc_plots::export_figures(std::path::Path::new(dir), &formats) {
            Ok(files) => files.iter().for_each(|f| println!("{}", f.display())),
            Err(e) => {
                eprintln!("export_figures: {e}");
                std::process::exit(1);
            }
        }
    }
}
