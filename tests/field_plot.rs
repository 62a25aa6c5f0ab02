//! `weft-plot field` puts the right colours in the right places (the PNG's pixels are
//! decoded and checked, not only its header).
//!
//! Reference: viridis, matplotlib's `_cm_listed.py` `_viridis_data` (CC0, Smith & van der
//! Walt), 8-bit: row 0 (0.267004, 0.004874, 0.329415) → (68, 1, 84); row 128 (0.127568,
//! 0.566949, 0.550556) → (33, 145, 140); row 255 (0.993248, 0.906157, 0.143936) →
//! (253, 231, 37).
//!
//! Case: a flat square plate L × L of 3 × 3 quads in the x–y plane; the test writes its
//! history by hand (no solver run), seen from +z:
//!
//! ```text
//!   y
//!   L +-----+-----+-----+      each quad is drawn as 3 × 3 pieces (SUBDIVISION)
//!     |     |     |     |      filled with the mean of the interpolated values:
//!     +-----+-----+-----+      with uz = x the nine piece columns carry
//!     |     |     |     |      (2k + 1) L/18, k = 0..8
//!     +-----+-----+-----+
//!     |     |     |     |
//!   0 +-----+-----+-----+--> x
//!     0                 L
//! ```

use std::path::Path;
use std::process::Command;

use weft::model::{ElementKind, Model, PartProps};
use weft::table::{batch, write_table, Col, Provenance};

const L: f64 = 0.03;
const VIRIDIS_0: [u8; 3] = [68, 1, 84];
const VIRIDIS_HALF: [u8; 3] = [33, 145, 140];
const VIRIDIS_1: [u8; 3] = [253, 231, 37];
/// Colour bar area at the right of the figure [px] (src/plot/field.rs BAR_WIDTH).
const BAR: usize = 130;

fn plate() -> Model {
    let mut m = Model::default();
    for j in 0..=3 {
        for i in 0..=3 {
            m.add_node(
                (j * 4 + i + 1) as i64,
                [L * i as f64 / 3.0, L * j as f64 / 3.0, 0.0],
            );
        }
    }
    let p = m.add_part(
        1,
        "plate",
        ElementKind::Quad,
        PartProps {
            youngs_modulus_1: Some(1e9),
            youngs_modulus_2: Some(1e9),
            shear_modulus_12: Some(4e8),
            thickness: Some(1e-3),
            density: Some(1000.0),
            ..Default::default()
        },
    );
    for j in 0..3 {
        for i in 0..3 {
            let n = |a: usize, b: usize| b * 4 + a;
            m.add_element(
                (j * 3 + i + 1) as i64,
                p,
                &[n(i, j), n(i + 1, j), n(i + 1, j + 1), n(i, j + 1)],
            );
        }
    }
    m
}

/// Writes the plate and a history whose uz at t = 1 ms is `uz(x)` (zero at t = 0).
fn write_case(dir: &Path, name: &str, uz: impl Fn(f64) -> f64) {
    let m = plate();
    let prov = Provenance::new("test field", serde_json::json!({}));
    weft::model::io::write_model(&m, &dir.join(name), &prov).unwrap();
    let n = m.num_nodes();
    let mut t = vec![0.0; n];
    t.extend(vec![1e-3; n]);
    let ids: Vec<i64> = m.node_id.iter().chain(&m.node_id).copied().collect();
    let mut w = vec![0.0; n];
    w.extend(m.coords.iter().map(|x| uz(x[0])));
    let zero = vec![0.0; 2 * n];
    write_table(
        &dir.join(format!("{name}.parquet")),
        &batch(vec![
            Col::F64("t", t),
            Col::I64("node_id", ids),
            Col::F64("ux", zero.clone()),
            Col::F64("uy", zero.clone()),
            Col::F64("uz", w),
            Col::F64("vx", zero.clone()),
            Col::F64("vy", zero.clone()),
            Col::F64("vz", zero),
        ]),
        &prov,
    )
    .unwrap();
}

fn plot(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_weft-plot"))
        .arg("field")
        .args(args)
        .output()
        .unwrap()
}

struct Image {
    w: usize,
    h: usize,
    rgb: Vec<u8>,
}

impl Image {
    fn read(p: &Path) -> Image {
        let dec = png::Decoder::new(std::fs::File::open(p).unwrap());
        let mut r = dec.read_info().unwrap();
        let mut buf = vec![0; r.output_buffer_size()];
        let info = r.next_frame(&mut buf).unwrap();
        assert_eq!(info.color_type, png::ColorType::Rgb, "plotters writes RGB");
        Image {
            w: info.width as usize,
            h: info.height as usize,
            rgb: buf[..info.buffer_size()].to_vec(),
        }
    }
    fn px(&self, x: usize, y: usize) -> [u8; 3] {
        let k = 3 * (y * self.w + x);
        [self.rgb[k], self.rgb[k + 1], self.rgb[k + 2]]
    }
    /// Bounding box of the coloured (not grey) pixels with x in [x0, x1).
    fn coloured_box(&self, x0: usize, x1: usize) -> (usize, usize, usize, usize) {
        let (mut a, mut b, mut c, mut d) = (usize::MAX, 0, usize::MAX, 0);
        for y in 0..self.h {
            for x in x0..x1 {
                let p = self.px(x, y);
                let (mx, mn) = (p.iter().max().unwrap(), p.iter().min().unwrap());
                if mx - mn > 40 {
                    a = a.min(x);
                    b = b.max(x);
                    c = c.min(y);
                    d = d.max(y);
                }
            }
        }
        assert!(a < b && c < d, "no coloured pixels in x = {x0}..{x1}");
        (a, b, c, d)
    }
}

fn close(got: [u8; 3], want: [u8; 3], tol: u8, what: &str) {
    let ok = (0..3).all(|k| got[k].abs_diff(want[k]) <= tol);
    eprintln!("{what}: {got:?} (published {want:?})");
    assert!(ok, "{what}: pixel {got:?}, expected {want:?} ± {tol}");
}

/// uz = x drawn with the range [L/18, 17L/18]: the first, middle and last piece columns
/// (values L/18, L/2, 17L/18) are viridis at 0, ½ and 1; the plate is square on screen.
#[test]
fn a_linear_field_has_the_published_viridis_colours_at_its_pieces() {
    let dir = tempfile::tempdir().unwrap();
    write_case(dir.path(), "plate", |x| x);
    let out = dir.path().join("f.png");
    let range = format!("{}:{}", L / 18.0, 17.0 * L / 18.0);
    let o = plot(&[
        "--model",
        dir.path().join("plate").to_str().unwrap(),
        "--history",
        dir.path().join("plate.parquet").to_str().unwrap(),
        "--time",
        "1e-3",
        "--range",
        &range,
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = Image::read(&out);
    assert_eq!((img.w, img.h), (1000, 650));
    let (x0, x1, y0, y1) = img.coloured_box(0, img.w - BAR);
    // Equal scales: a square plate is square on screen (measured: 518 × 517 px).
    let (wpx, hpx) = (x1 - x0, y1 - y0);
    eprintln!("plate on screen: {wpx} × {hpx} px");
    assert!(wpx.abs_diff(hpx) <= 2, "plate {wpx} × {hpx} px");
    assert!(wpx > 300, "the plate fills the panel: {wpx} px");
    let y = (y0 + y1) / 2;
    let at = |k: usize| img.px(x0 + (2 * k + 1) * wpx / 18, y);
    // Measured: equal at the pieces; the colour bar's end bands (their mid value, 1/512
    // from the end) 1 apart.
    close(
        at(0),
        VIRIDIS_0,
        2,
        "piece column 0 (value L/18: bottom of range)",
    );
    close(at(4), VIRIDIS_HALF, 2, "piece column 4 (value L/2: middle)");
    close(at(8), VIRIDIS_1, 2, "piece column 8 (value 17L/18: top)");
    // The colour bar's bottom and top are the map's ends.
    let (b0, b1, c0, c1) = img.coloured_box(img.w - BAR, img.w);
    close(
        img.px((b0 + b1) / 2, c1 - 1),
        VIRIDIS_0,
        2,
        "colour bar bottom",
    );
    close(
        img.px((b0 + b1) / 2, c0 + 1),
        VIRIDIS_1,
        2,
        "colour bar top",
    );
}

/// Two panels on one colour scale: A is 0 on its left column of quads and L on its right
/// column; B = A + L. The default range is [0, 2L] over both, so A's right column is
/// viridis(½), the colour of B's left column, and only B's right column is yellow (each
/// panel on its own scale would make both right columns yellow).
#[test]
fn two_models_share_one_colour_scale() {
    let dir = tempfile::tempdir().unwrap();
    let step = |x: f64| if x > 0.5 * L { L } else { 0.0 };
    write_case(dir.path(), "a", step);
    write_case(dir.path(), "b", |x| step(x) + L);
    let out = dir.path().join("f.png");
    let p = |s: &str| dir.path().join(s).to_str().unwrap().to_string();
    let o = plot(&[
        "--model",
        &p("a"),
        "--history",
        &p("a.parquet"),
        "--label",
        "A",
        "--model",
        &p("b"),
        "--history",
        &p("b.parquet"),
        "--label",
        "B",
        "--time",
        "1e-3",
        "--out",
        &p("f.png"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("colour range 0e0 .. 6e-2"), "{err}");
    let img = Image::read(&out);
    let half = (img.w - BAR) / 2;
    for (panel, (x0, x1), left, right) in [
        ("A", (0, half), VIRIDIS_0, VIRIDIS_HALF),
        ("B", (half, img.w - BAR), VIRIDIS_HALF, VIRIDIS_1),
    ] {
        let (a, b, c, d) = img.coloured_box(x0, x1);
        let y = (c + d) / 2;
        close(
            img.px(a + (b - a) / 6, y),
            left,
            2,
            &format!("{panel}, left"),
        );
        close(
            img.px(a + 5 * (b - a) / 6, y),
            right,
            2,
            &format!("{panel}, right"),
        );
    }
}

#[test]
fn the_field_figure_writes_svg_with_one_polygon_per_piece() {
    let dir = tempfile::tempdir().unwrap();
    write_case(dir.path(), "plate", |x| x);
    let out = dir.path().join("f.svg");
    let o = plot(&[
        "--model",
        dir.path().join("plate").to_str().unwrap(),
        "--history",
        dir.path().join("plate.parquet").to_str().unwrap(),
        "--time",
        "1e-3",
        "--deformed",
        "--scale",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let svg = std::fs::read_to_string(&out).unwrap();
    // 9 quads × 3 × 3 pieces, plus the colour bar's 256 bands (rectangles).
    assert_eq!(svg.matches("<polygon").count(), 81, "pieces");
    assert!(svg.contains("deformed ×2"));
}

#[test]
fn bad_field_requests_say_what_and_where() {
    let dir = tempfile::tempdir().unwrap();
    write_case(dir.path(), "plate", |x| x);
    let model = dir.path().join("plate");
    let hist = dir.path().join("plate.parquet");
    let out = dir.path().join("x.png");
    let base = |extra: &[&str]| {
        let mut args = vec!["--model", model.to_str().unwrap()];
        args.extend([
            "--history",
            hist.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        args.extend(extra);
        let o = plot(&args);
        assert!(!o.status.success(), "{extra:?} should fail");
        assert!(!out.exists(), "no figure on failure");
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    let e = base(&["--time", "5e-3"]);
    assert!(
        e.contains("outside the history") && e.contains("plate.parquet") && e.contains("1e-3"),
        "{e}"
    );
    let e = base(&["--time", "1e-3", "--component", "uw"]);
    assert!(
        e.contains("unknown component `uw`") && e.contains("ux, uy, uz"),
        "{e}"
    );
    let e = base(&["--time", "1e-3", "--view", "zz"]);
    assert!(e.contains("--view `zz`"), "{e}");
    let e = base(&["--time", "1e-3", "--range", "3:1"]);
    assert!(e.contains("--range 3:1") && e.contains("MIN < MAX"), "{e}");
    // A history of other nodes (ids shifted): nothing to colour.
    let prov = Provenance::new("test", serde_json::json!({}));
    write_table(
        &hist,
        &batch(vec![
            Col::F64("t", vec![0.0]),
            Col::I64("node_id", vec![999]),
            Col::F64("ux", vec![0.0]),
            Col::F64("uy", vec![0.0]),
            Col::F64("uz", vec![0.0]),
            Col::F64("vx", vec![0.0]),
            Col::F64("vy", vec![0.0]),
            Col::F64("vz", vec![0.0]),
        ]),
        &prov,
    )
    .unwrap();
    let e = base(&["--time", "0"]);
    assert!(e.contains("no node of model") && e.contains("hint:"), "{e}");
}
