//! Figures in other formats: the format list, and PNG and PDF files with their text.

use resvg::tiny_skia::Pixmap;
use sc_plots::{FigureFormat, FigureFormats, PNG_SCALE, export_figure, export_figures};
use std::path::{Path, PathBuf};

/// A scratch directory, removed when the test ends.
struct TmpDir(PathBuf);

impl Drop for TmpDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn tmp(name: &str) -> TmpDir {
    let d = std::env::temp_dir().join(format!("sc-plots-export-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    TmpDir(d)
}

/// A small figure that is only text on white, as plotters writes it.
const TEXT_ONLY: &str = r##"<svg width="120" height="40" viewBox="0 0 120 40" xmlns="http://www.w3.org/2000/svg">
<rect x="0" y="0" width="120" height="40" opacity="1" fill="#FFFFFF" stroke="none"/>
<text x="60" y="12" dy="0.76em" text-anchor="middle" font-family="sans-serif" font-size="14" opacity="1" fill="#000000">
h = 0, τ_M [N m]
</text>
</svg>
"##;

fn png_size(bytes: &[u8]) -> (u32, u32) {
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&bytes[12..16], b"IHDR");
    let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
    (be(&bytes[16..20]), be(&bytes[20..24]))
}

#[test]
fn formats_parse_and_name_the_bad_entry() {
    let all = FigureFormats::parse("svg,png,pdf").unwrap();
    assert_eq!(
        all.iter().collect::<Vec<_>>(),
        [FigureFormat::Svg, FigureFormat::Png, FigureFormat::Pdf]
    );
    assert_eq!(all.to_string(), "svg,png,pdf");
    // SVG always; order and case do not matter; repeats ignored
    let p: FigureFormats = " PDF ,png,pdf".parse().unwrap();
    assert_eq!(p, all);
    assert!(FigureFormats::parse("svg").unwrap() == FigureFormats::default());
    assert!(!FigureFormats::default().needs_conversion());
    for (bad, says) in [
        ("svg,jpg", "unknown figure format `jpg`"),
        ("", "no figure format given"),
        ("png,,pdf", "empty entry"),
        ("eps", "unknown figure format `eps`"),
    ] {
        let m = FigureFormats::parse(bad).unwrap_err().to_string();
        assert!(m.contains(says), "{bad:?}: {m}");
        assert!(
            m.contains("svg, png, pdf") && !m.contains('\n'),
            "{bad:?}: {m}"
        );
    }
}

#[test]
fn png_and_pdf_are_written_with_their_text_and_deterministic() {
    let d = tmp("text");
    let svg = d.0.join("label.svg");
    std::fs::write(&svg, TEXT_ONLY).unwrap();
    std::fs::write(d.0.join("notes.txt"), "not a figure").unwrap();
    let formats = FigureFormats::parse("svg,png,pdf").unwrap();
    let out = export_figures(&d.0, &formats).unwrap();
    assert_eq!(out, [d.0.join("label.png"), d.0.join("label.pdf")]);

    let png = std::fs::read(d.0.join("label.png")).unwrap();
    assert_eq!(
        png_size(&png),
        ((120.0 * PNG_SCALE) as u32, (40.0 * PNG_SCALE) as u32)
    );
    // the text is drawn: dark pixels on the white figure
    let pix = Pixmap::decode_png(&png).unwrap();
    let dark = pix
        .pixels()
        .iter()
        .filter(|p| p.red() < 128 && p.alpha() == 255)
        .count();
    assert!(dark > 50, "text rendered: {dark} dark pixels");

    let pdf = std::fs::read(d.0.join("label.pdf")).unwrap();
    assert!(pdf.starts_with(b"%PDF-"), "PDF header");
    assert!(
        pdf.windows(b"/FontFile2".len()).any(|w| w == b"/FontFile2"),
        "text embedded as text, with its font"
    );

    // identical input, identical files
    let again = export_figure(&svg, &formats).unwrap();
    assert_eq!(again.len(), 2);
    assert_eq!(std::fs::read(d.0.join("label.png")).unwrap(), png);
    assert_eq!(std::fs::read(d.0.join("label.pdf")).unwrap(), pdf);
    // the SVG is kept
    assert_eq!(std::fs::read_to_string(&svg).unwrap(), TEXT_ONLY);
}

#[test]
fn export_reports_bad_input_in_one_line() {
    let d = tmp("bad");
    let png = FigureFormats::parse("png").unwrap();
    // SVG only: nothing to do, not even a folder to read
    assert!(
        export_figures(Path::new("/nonexistent/figures"), &FigureFormats::default())
            .unwrap()
            .is_empty()
    );
    let m = export_figures(Path::new("/nonexistent/figures"), &png)
        .unwrap_err()
        .to_string();
    assert!(
        m.contains("/nonexistent/figures") && !m.contains('\n'),
        "{m}"
    );
    std::fs::write(d.0.join("broken.svg"), "<svg").unwrap();
    let m = export_figures(&d.0, &png).unwrap_err().to_string();
    assert!(m.contains("broken.svg") && !m.contains('\n'), "{m}");
    assert!(!d.0.join("broken.png").exists());
}

#[test]
fn real_figures_convert() {
    // a figure as the crate draws it: every text set, both formats written
    let d = tmp("real");
    let diffs: Vec<sc_mission::compare::StepDifference> = (0..20)
        .map(|i| sc_mission::compare::StepDifference {
            t: i as f64,
            hill_position_m: 1e-12 * (i + 1) as f64,
            attitude_rad: 1e-9,
            joint_angle_rad: 0.0,
            target_attitude_rad: 1e-6,
        })
        .collect();
    sc_plots::difference_figure(&d.0.join("compare.svg"), &diffs, "A against B").unwrap();
    let out = export_figures(&d.0, &FigureFormats::parse("pdf,png").unwrap()).unwrap();
    assert_eq!(out.len(), 2);
    let (w, h) = png_size(&std::fs::read(&out[0]).unwrap());
    assert_eq!(
        (w, h),
        ((900.0 * PNG_SCALE) as u32, (450.0 * PNG_SCALE) as u32)
    );
}
