//! Figures in other formats: every SVG of a folder converted to PNG (resvg) and PDF
//! (svg2pdf, text kept as text), in pure Rust. Text is set in a font found among the
//! system's fonts (on Debian/Ubuntu: `fonts-dejavu-core`); with no font found the
//! conversion fails with an error saying so, and a text the renderer could not set is an
//! error too, never silently dropped. Output is a pure function of the SVG and the fonts.

use crate::PlotError;
use resvg::tiny_skia;
use resvg::usvg;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::{Arc, OnceLock};

/// Pixels of PNG per SVG pixel (figures are drawn for the screen; print wants more).
pub const PNG_SCALE: f32 = 2.0;

/// Sans-serif families chosen for `sans-serif`, in order, when installed (the first two
/// ship with Debian's and Ubuntu's font packages `fonts-dejavu-core` and
/// `fonts-liberation`).
const SANS_SERIF: [&str; 6] = [
    "DejaVu Sans",
    "Liberation Sans",
    "Noto Sans",
    "FreeSans",
    "Arial",
    "Helvetica",
];

/// What a user is told to do when no font is found.
const NO_FONT_HINT: &str = "no font found for figure text in the system font folders \
    (/usr/share/fonts, /usr/local/share/fonts, ~/.local/share/fonts); install one, e.g. \
    `apt-get install fonts-dejavu-core`";

/// Why an SVG could not be converted (inside [`PlotError::Export`]).
#[derive(Debug, thiserror::Error)]
pub enum ConvertError {
    /// The SVG is not well-formed XML.
    #[error(transparent)]
    Xml(#[from] usvg::roxmltree::Error),
    /// The renderer could not read the SVG.
    #[error(transparent)]
    Svg(#[from] usvg::Error),
    /// Texts the renderer could not set in the font (they would be dropped silently).
    #[error("{missing} of {want} texts could not be set in the font `{family}`")]
    TextNotSet {
        missing: usize,
        want: usize,
        family: String,
    },
    /// The PNG's size overflows.
    #[error("figure too large")]
    TooLarge,
    #[error("cannot allocate {width}x{height} pixels")]
    Pixels { width: u32, height: u32 },
    /// The PNG encoder's message.
    #[error("{0}")]
    Png(String),
    /// The PDF converter's message.
    #[error("{0}")]
    Pdf(String),
}

/// One figure file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum FigureFormat {
    /// The figures as drawn (always written).
    Svg,
    /// Raster, [`PNG_SCALE`] pixels per SVG pixel.
    Png,
    /// Vector, text embedded as text (subset fonts), one page per figure.
    Pdf,
}

impl FigureFormat {
    /// Every format, in the order of [`FigureFormat::extension`]'s documentation.
    pub const ALL: [FigureFormat; 3] = [FigureFormat::Svg, FigureFormat::Png, FigureFormat::Pdf];

    /// The file extension, also the name on the command line: `svg`, `png`, `pdf`.
    pub fn extension(self) -> &'static str {
        match self {
            FigureFormat::Svg => "svg",
            FigureFormat::Png => "png",
            FigureFormat::Pdf => "pdf",
        }
    }
}

impl std::fmt::Display for FigureFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.extension())
    }
}

impl FromStr for FigureFormat {
    type Err = PlotError;
    fn from_str(s: &str) -> Result<Self, PlotError> {
        let t = s.trim();
        FigureFormat::ALL
            .into_iter()
            .find(|f| f.extension().eq_ignore_ascii_case(t))
            .ok_or_else(|| PlotError::Format {
                message: format!("unknown figure format `{t}` (known: svg, png, pdf)"),
            })
    }
}

/// The formats figures are written in: SVG always, PNG and PDF as asked. Parsed from a
/// comma-separated list such as `svg,png,pdf` (case-insensitive, repeats ignored).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct FigureFormats(Vec<FigureFormat>);

impl Default for FigureFormats {
    /// SVG only.
    fn default() -> Self {
        Self(vec![FigureFormat::Svg])
    }
}

impl FigureFormats {
    /// Parses `svg,png,pdf`; one line naming the bad entry otherwise.
    pub fn parse(s: &str) -> Result<Self, PlotError> {
        let mut out = vec![FigureFormat::Svg];
        if s.trim().is_empty() {
            return Err(PlotError::Format {
                message: "no figure format given (known: svg, png, pdf)".into(),
            });
        }
        for part in s.split(',') {
            if part.trim().is_empty() {
                return Err(PlotError::Format {
                    message: format!("empty entry in figure formats `{s}` (known: svg, png, pdf)"),
                });
            }
            let f: FigureFormat = part.parse()?;
            if !out.contains(&f) {
                out.push(f);
            }
        }
        out.sort();
        Ok(Self(out))
    }

    /// These formats.
    pub fn new(formats: impl IntoIterator<Item = FigureFormat>) -> Self {
        let mut out = vec![FigureFormat::Svg];
        for f in formats {
            if !out.contains(&f) {
                out.push(f);
            }
        }
        out.sort();
        Self(out)
    }

    pub fn contains(&self, f: FigureFormat) -> bool {
        self.0.contains(&f)
    }

    /// The formats in order: svg, png, pdf.
    pub fn iter(&self) -> impl Iterator<Item = FigureFormat> + '_ {
        self.0.iter().copied()
    }

    /// Whether anything beyond SVG is asked for.
    pub fn needs_conversion(&self) -> bool {
        self.0.iter().any(|f| *f != FigureFormat::Svg)
    }
}

impl FromStr for FigureFormats {
    type Err = PlotError;
    fn from_str(s: &str) -> Result<Self, PlotError> {
        Self::parse(s)
    }
}

impl std::fmt::Display for FigureFormats {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let names: Vec<&str> = self.0.iter().map(|x| x.extension()).collect();
        f.write_str(&names.join(","))
    }
}

/// The system fonts with `sans-serif` mapped to an installed family, loaded once.
/// Whether `formats` can be written on this machine: `Ok` when only SVG is asked for or a
/// system font for the figures' text is installed (what a command checks before it runs,
/// so that a missing font does not surface after a long campaign).
pub fn check_formats(formats: &FigureFormats) -> Result<(), PlotError> {
    if formats.needs_conversion() {
        fonts()?;
    }
    Ok(())
}

fn fonts() -> Result<Arc<usvg::fontdb::Database>, PlotError> {
    // `None`: no font installed
    static DB: OnceLock<Option<Arc<usvg::fontdb::Database>>> = OnceLock::new();
    DB.get_or_init(|| {
        let mut db = usvg::fontdb::Database::new();
        db.load_system_fonts();
        let family = pick_family(&db)?;
        db.set_sans_serif_family(family.clone());
        db.set_serif_family(family.clone());
        db.set_monospace_family(family.clone());
        db.set_cursive_family(family.clone());
        db.set_fantasy_family(family);
        Some(Arc::new(db))
    })
    .clone()
    .ok_or_else(|| PlotError::Font {
        message: NO_FONT_HINT.to_string(),
    })
}

/// The preferred installed sans-serif family, else the alphabetically first family.
fn pick_family(db: &usvg::fontdb::Database) -> Option<String> {
    let mut families: Vec<&str> = db
        .faces()
        .flat_map(|f| f.families.iter().map(|(name, _)| name.as_str()))
        .collect();
    families.sort_unstable();
    families.dedup();
    SANS_SERIF
        .iter()
        .find(|want| families.contains(want))
        .map(|s| s.to_string())
        .or_else(|| families.first().map(|s| s.to_string()))
}

/// Number of `<text>` elements of `svg` with something to show.
fn texts_in_source(svg: &str) -> Result<usize, ConvertError> {
    let doc = usvg::roxmltree::Document::parse(svg)?;
    Ok(doc
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .filter(|n| {
            n.descendants()
                .filter_map(|d| d.text())
                .any(|t| !t.trim().is_empty())
        })
        .count())
}

/// Number of text nodes the renderer set.
fn texts_in_tree(g: &usvg::Group) -> usize {
    g.children()
        .iter()
        .map(|n| match n {
            usvg::Node::Group(g) => texts_in_tree(g),
            usvg::Node::Text(_) => 1,
            _ => 0,
        })
        .sum()
}

/// Parses `svg` with the fonts; an error if any text could not be set.
fn parse(svg: &str, fonts: Arc<usvg::fontdb::Database>) -> Result<usvg::Tree, ConvertError> {
    let family = fonts
        .family_name(&usvg::fontdb::Family::SansSerif)
        .to_string();
    let options = usvg::Options {
        font_family: family.clone(),
        fontdb: fonts,
        ..Default::default()
    };
    let tree = usvg::Tree::from_str(svg, &options)?;
    let (want, got) = (texts_in_source(svg)?, texts_in_tree(tree.root()));
    if got < want {
        return Err(ConvertError::TextNotSet {
            missing: want - got,
            want,
            family,
        });
    }
    Ok(tree)
}

/// The PNG of `tree`: [`PNG_SCALE`] pixels per SVG pixel, white where the SVG is clear.
fn png(tree: &usvg::Tree) -> Result<Vec<u8>, ConvertError> {
    let size = tree
        .size()
        .to_int_size()
        .scale_by(PNG_SCALE)
        .ok_or(ConvertError::TooLarge)?;
    let mut pixmap =
        tiny_skia::Pixmap::new(size.width(), size.height()).ok_or(ConvertError::Pixels {
            width: size.width(),
            height: size.height(),
        })?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(
        tree,
        tiny_skia::Transform::from_scale(PNG_SCALE, PNG_SCALE),
        &mut pixmap.as_mut(),
    );
    pixmap
        .encode_png()
        .map_err(|e| ConvertError::Png(e.to_string()))
}

/// The PDF of `tree`, one page of the figure's size (1 SVG pixel = 1 pt).
fn pdf(tree: &usvg::Tree) -> Result<Vec<u8>, ConvertError> {
    svg2pdf::to_pdf(
        tree,
        svg2pdf::ConversionOptions::default(),
        svg2pdf::PageOptions::default(),
    )
    .map_err(|e| ConvertError::Pdf(e.to_string()))
}

/// Converts `svg_path` into the formats of `formats` other than SVG, beside it (same
/// name, other extension); returns the files written.
pub fn export_figure(svg_path: &Path, formats: &FigureFormats) -> Result<Vec<PathBuf>, PlotError> {
    if !formats.needs_conversion() {
        return Ok(Vec::new());
    }
    let shown = svg_path.display().to_string();
    let io = |path: &Path, err: std::io::Error| PlotError::Io {
        path: path.display().to_string(),
        message: err.to_string(),
    };
    let text = std::fs::read_to_string(svg_path).map_err(|err| io(svg_path, err))?;
    let tree = parse(&text, fonts()?).map_err(|source| PlotError::Export {
        path: shown.clone(),
        source,
    })?;
    let mut out = Vec::new();
    for f in formats.iter() {
        let bytes = match f {
            FigureFormat::Svg => continue,
            FigureFormat::Png => png(&tree),
            FigureFormat::Pdf => pdf(&tree),
        }
        .map_err(|source| PlotError::Export {
            path: format!("{shown} as {f}"),
            source,
        })?;
        let target = svg_path.with_extension(f.extension());
        std::fs::write(&target, bytes).map_err(|err| io(&target, err))?;
        out.push(target);
    }
    Ok(out)
}

/// Converts every `*.svg` directly in `dir` (not in sub-folders) into the formats of
/// `formats` other than SVG, beside it; returns the files written, in name order. The
/// SVGs are kept. Nothing to do (and no font needed) when only SVG is asked for.
pub fn export_figures(dir: &Path, formats: &FigureFormats) -> Result<Vec<PathBuf>, PlotError> {
    if !formats.needs_conversion() {
        return Ok(Vec::new());
    }
    let io = |err: std::io::Error| PlotError::Io {
        path: dir.display().to_string(),
        message: err.to_string(),
    };
    let mut svgs = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let p = entry.map_err(io)?.path();
        let is_svg = p
            .extension()
            .is_some_and(|x| x.eq_ignore_ascii_case(FigureFormat::Svg.extension()));
        if is_svg && p.is_file() {
            svgs.push(p);
        }
    }
    svgs.sort();
    let mut out = Vec::new();
    for p in svgs {
        out.extend(export_figure(&p, formats)?);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = r##"<svg width="80" height="20" xmlns="http://www.w3.org/2000/svg">
<text x="4" y="4" font-family="sans-serif" font-size="12">h = 0</text>
<text x="4" y="14" font-family="sans-serif" font-size="12">   </text>
</svg>"##;

    #[test]
    fn text_without_a_font_is_an_error_not_a_blank() {
        let empty = Arc::new(usvg::fontdb::Database::new());
        assert_eq!(pick_family(&empty), None);
        let m = parse(TEXT, empty).unwrap_err().to_string();
        assert!(m.contains("1 of 1 texts could not be set"), "{m}");
        assert_eq!(texts_in_source(TEXT).unwrap(), 1);
    }

    #[test]
    fn the_preferred_family_is_chosen_when_installed() {
        let db = fonts().unwrap();
        let family = db.family_name(&usvg::fontdb::Family::SansSerif).to_string();
        let installed: Vec<&str> = db
            .faces()
            .flat_map(|f| f.families.iter().map(|(n, _)| n.as_str()))
            .collect();
        assert!(installed.contains(&family.as_str()), "{family}");
        if let Some(want) = SANS_SERIF.iter().find(|w| installed.contains(w)) {
            assert_eq!(&family, want);
        }
        assert!(parse(TEXT, db).is_ok());
    }
}
