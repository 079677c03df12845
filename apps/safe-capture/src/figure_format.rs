//! `--figure-format`: every command that draws figures writes them as SVG and, on request,
//! as PNG and PDF beside each SVG ([`sc_plots::export_figures`]).

use std::path::Path;

/// The figure formats of one command.
#[derive(clap::Args, Clone, Debug)]
pub struct FigureFormatArg {
    /// Figure formats, comma-separated: `svg` (always written), `png` (twice the SVG's
    /// pixel size), `pdf` (vector, text kept as text) — e.g. `svg,png,pdf`. PNG and PDF
    /// need a system font (scripts/setup.sh installs one when the machine has none).
    #[arg(long = "figure-format", value_name = "LIST", default_value = "svg")]
    pub formats: sc_plots::FigureFormats,
}

impl FigureFormatArg {
    /// Before the command runs: the requested formats can be written here (a font for
    /// PNG/PDF), so that a missing font does not surface after a long run.
    pub fn check(&self) -> anyhow::Result<()> {
        sc_plots::check_formats(&self.formats)?;
        Ok(())
    }

    /// Converts every SVG in `dir` (not its sub-folders) into the other requested formats.
    pub fn export_dir(&self, dir: &Path) -> anyhow::Result<()> {
        sc_plots::export_figures(dir, &self.formats)?;
        Ok(())
    }

    /// Converts the one figure `svg`.
    pub fn export_file(&self, svg: &Path) -> anyhow::Result<()> {
        sc_plots::export_figure(svg, &self.formats)?;
        Ok(())
    }
}
