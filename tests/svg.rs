//! Integration tests: SVG import (spec "Inputs", T2D), sampling (section 3)
//! and the antenna generators.
use pcpp::demo::antennas::{
    archimedean_spiral_svg, hilbert_loop_svg, paper_spiral_svg, triangular_monopole_svg,
    PAPER_SPIRAL_LENGTH_MM,
};
use pcpp::sampling::{sample_subpath, try_sample_subpath_marked};
use pcpp::svg::{import_svg, import_svg_with_notes, Placement, Subpath2, SvgError};
use pcpp::DVec2;

// Shapes other than paths, and `use` instances, carry usvg's f32 numbers
// (about 1e-7 relative): 1e-5 mm is the tolerance for positions in a
// 100 mm drawing. The scale from user units to mm is f64 (the tests after
// "user units to mm, in f64" compare exactly).
const MM: &str = r#"width="100mm" height="100mm" viewBox="0 0 100 100""#;

fn doc(size: &str, body: &str) -> String {
    format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" {size}>{body}</svg>"#
    )
}

fn import(text: &str) -> Vec<Subpath2> {
    match import_svg(text.as_bytes(), "test.svg") {
        Ok(v) => v,
        Err(e) => panic!("import failed: {e}\n{text}"),
    }
}

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

fn assert_near(a: DVec2, b: DVec2, tol: f64) {
    assert!(a.distance(b) <= tol, "{a} vs {b} (tol {tol})");
}

fn corner_points(s: &Subpath2) -> Vec<DVec2> {
    s.points
        .iter()
        .zip(&s.corner)
        .filter(|(_, &c)| c)
        .map(|(&p, _)| p)
        .collect()
}

// ---------------------------------------------------------------- shapes

#[test]
fn circle_is_exact_round_and_smooth() {
    let subs = import(&doc(
        MM,
        r#"<circle cx="30" cy="20" r="5" stroke="black" fill="none"/>"#,
    ));
    assert_eq!(subs.len(), 1);
    let c = &subs[0];
    assert!(c.closed);
    assert!(c.points.len() > 100);
    assert_eq!(c.points.first(), c.points.last());
    assert_near(c.points[0], v(35.0, -20.0), 1e-5);
    for p in &c.points {
        assert!((p.distance(v(30.0, -20.0)) - 5.0).abs() <= 1e-4, "{p}");
    }
    // Chord midpoints too: the flattening error, not just the vertices.
    for w in c.points.windows(2) {
        let m = (w[0] + w[1]) * 0.5;
        assert!(5.0 - m.distance(v(30.0, -20.0)) <= 1e-4);
    }
    assert!(c.corner.iter().all(|&k| !k), "a circle has no corners");
    assert_eq!(c.source, "circle #1");
}

#[test]
fn ellipse_points_satisfy_its_equation() {
    let subs = import(&doc(
        MM,
        r#"<ellipse id="e" cx="50" cy="50" rx="10" ry="4" stroke="black" fill="none"/>"#,
    ));
    assert_eq!(subs.len(), 1);
    assert_eq!(subs[0].source, "e");
    for p in &subs[0].points {
        let q = *p - v(50.0, -50.0);
        let f = (q.x / 10.0).powi(2) + (q.y / 4.0).powi(2);
        assert!((f - 1.0).abs() < 1e-6, "{p}");
    }
    assert!(subs[0].corner.iter().all(|&k| !k));
}

#[test]
fn rect_in_a_scaled_viewbox_is_in_mm_with_four_corners() {
    let subs = import(&doc(
        r#"width="20mm" height="10mm" viewBox="0 0 200 100""#,
        r#"<rect x="10" y="10" width="20" height="10" stroke="black" fill="none"/>"#,
    ));
    assert_eq!(subs.len(), 1);
    let r = &subs[0];
    assert!(r.closed);
    assert_eq!(r.points.len(), 5, "4 corners + the closing point");
    assert_eq!(r.corner, vec![true; 5]);
    let expect = [
        v(1.0, -1.0),
        v(3.0, -1.0),
        v(3.0, -2.0),
        v(1.0, -2.0),
        v(1.0, -1.0),
    ];
    for (p, e) in r.points.iter().zip(expect) {
        assert_near(*p, e, 1e-5);
    }
    assert!((r.length_mm() - 6.0).abs() < 1e-6);
}

#[test]
fn rounded_rect_has_exact_quarter_circles_and_no_corners() {
    let subs = import(&doc(
        MM,
        r#"<rect x="10" y="10" width="30" height="20" rx="4" stroke="black" fill="none"/>"#,
    ));
    assert_eq!(subs.len(), 1);
    let r = &subs[0];
    assert!(r.closed && r.corner.iter().all(|&k| !k));
    // Every point is on a straight side or on a corner circle of radius 4.
    let centres = [
        v(14.0, -14.0),
        v(36.0, -14.0),
        v(36.0, -26.0),
        v(14.0, -26.0),
    ];
    for p in &r.points {
        let on_side = (p.x - 10.0).abs() < 1e-5
            || (p.x - 40.0).abs() < 1e-5
            || (p.y + 10.0).abs() < 1e-5
            || (p.y + 30.0).abs() < 1e-5;
        let on_arc = centres
            .iter()
            .any(|c| (p.distance(*c) - 4.0).abs() < 1e-4 && (p.x - c.x).abs() <= 4.0);
        assert!(on_side || on_arc, "{p}");
    }
    let expected = 2.0 * (22.0 + 12.0) + std::f64::consts::TAU * 4.0;
    // The polyline is shorter than the true curve by its chord error only.
    assert!((r.length_mm() - expected).abs() < 1e-3);
}

#[test]
fn polygon_polyline_and_line() {
    let subs = import(&doc(
        MM,
        r#"<polygon points="0,0 10,0 10,10" stroke="black" fill="none"/>
           <polyline points="20,0 30,0 40,0 40,10" stroke="black" fill="none"/>
           <line x1="0" y1="50" x2="10" y2="50" stroke="black"/>"#,
    ));
    assert_eq!(subs.len(), 3);
    assert!(subs[0].closed);
    assert_eq!(subs[0].points.len(), 4);
    assert_eq!(subs[0].corner, vec![true; 4]);
    let pl = &subs[1];
    assert!(!pl.closed);
    // The collinear middle vertex (30, 0) is not a corner; the ends are.
    assert_eq!(pl.corner, vec![true, false, true, true]);
    assert_near(subs[2].points[0], v(0.0, -50.0), 1e-5);
    assert_near(subs[2].points[1], v(10.0, -50.0), 1e-5);
    assert_eq!(subs[2].corner, vec![true, true]);
    assert_eq!(subs[2].source, "line #3");
}

// ---------------------------------------------------------- path commands

const ABSOLUTE: &str = "M 10 10 L 20 10 H 30 V 20 C 30 30 20 30 20 25 S 10 20 10 25 \
                        Q 5 30 0 25 T -10 25 A 5 5 0 0 1 -20 25 Z M 50 50 L 60 60";
const RELATIVE: &str = "m 10 10 l 10 0 h 10 v 10 c 0 10 -10 10 -10 5 s -10 -5 -10 0 \
                        q -5 5 -10 0 t -10 0 a 5 5 0 0 1 -10 0 z m 40 40 l 10 10";

#[test]
fn relative_and_absolute_commands_agree() {
    let body = |d: &str| format!(r#"<path d="{d}" stroke="black" fill="none"/>"#);
    let a = import(&doc(MM, &body(ABSOLUTE)));
    let r = import(&doc(MM, &body(RELATIVE)));
    assert_eq!(a.len(), 2, "each M starts a subpath");
    assert_eq!(r.len(), 2);
    for (sa, sr) in a.iter().zip(&r) {
        assert_eq!(sa.points.len(), sr.points.len());
        assert_eq!(sa.corner, sr.corner);
        for (p, q) in sa.points.iter().zip(&sr.points) {
            assert_near(*p, *q, 1e-9);
        }
    }
    assert!(a[0].closed && !a[1].closed);
    assert_eq!(a[0].points.first(), a[0].points.last());
}

#[test]
fn corner_flags_follow_the_drawn_tangent() {
    let subs = import(&doc(
        MM,
        &format!(r#"<path d="{ABSOLUTE}" stroke="black" fill="none"/>"#),
    ));
    let s = &subs[0];
    let corners = corner_points(s);
    let is_corner = |p: DVec2| corners.iter().any(|c| c.distance(p) < 1e-5);
    let is_point = |p: DVec2| s.points.iter().any(|c| c.distance(p) < 1e-5);
    // Real kinks: H -> V, S -> Q (45 deg), T -> A, A -> the closing line,
    // and the closing line -> the first L at the start.
    for p in [
        v(10.0, -10.0),
        v(30.0, -10.0),
        v(10.0, -25.0),
        v(-10.0, -25.0),
        v(-20.0, -25.0),
    ] {
        assert!(is_corner(p), "{p} should be a corner");
    }
    // A vertex on a straight run, V into a C leaving the same way, and the
    // S and T joins (which reflect the previous control point) are smooth.
    for p in [
        v(20.0, -10.0),
        v(30.0, -20.0),
        v(20.0, -25.0),
        v(0.0, -25.0),
    ] {
        assert!(is_point(p) && !is_corner(p), "{p} should be smooth");
    }
    // Only the joins are corners, never points inside a curve; the closed
    // start counts twice (first and repeated last point).
    assert_eq!(corners.len(), 6, "{corners:?}");
}

#[test]
fn arcs_are_exact_including_large_and_rotated() {
    let subs = import(&doc(
        MM,
        r#"<path d="M 0 0 A 10 10 0 0 1 20 0" stroke="black" fill="none"/>
           <path d="M 0 50 A 10 10 0 1 0 10 60" stroke="black" fill="none"/>
           <path d="M 50 50 a 20 10 30 1 1 10 5" stroke="black" fill="none"/>
           <path d="M 80 80 A 1 1 0 0 1 90 80" stroke="black" fill="none"/>"#,
    ));
    assert_eq!(subs.len(), 4);
    // Half circle, sweep flag 1 (clockwise on screen): it bulges to -y in
    // SVG, so +y after the flip.
    for p in &subs[0].points {
        assert!((p.distance(v(10.0, 0.0)) - 10.0).abs() < 1e-4);
        assert!(p.y >= -1e-5);
    }
    // Large arc: three quarters of a circle around (0, 60) in SVG.
    let l = &subs[1];
    for p in &l.points {
        assert!((p.distance(v(0.0, -60.0)) - 10.0).abs() < 1e-4);
    }
    let quarter = std::f64::consts::FRAC_PI_2 * 10.0;
    assert!((l.length_mm() - 3.0 * quarter).abs() < 1e-3);
    // Rotated ellipse: every point satisfies the rotated ellipse equation
    // for some centre; check the end points are exact and it is smooth.
    let e = &subs[2];
    assert_near(e.points[0], v(50.0, -50.0), 1e-5);
    assert_near(
        *e.points.last().unwrap_or(&DVec2::NAN),
        v(60.0, -55.0),
        1e-5,
    );
    assert_eq!(corner_points(e).len(), 2);
    // Radii too small: scaled up to a half circle of radius 5 (SVG F.6.6).
    let s = &subs[3];
    for p in &s.points {
        assert!((p.distance(v(85.0, -80.0)) - 5.0).abs() < 1e-4);
    }
}

// ----------------------------------------------------------- structure

#[test]
fn transforms_on_nested_groups() {
    let subs = import(&doc(
        MM,
        r#"<g transform="translate(10,5)">
             <g transform="rotate(90)">
               <g transform="scale(2)"><path d="M 0 0 L 1 0" stroke="black"/></g>
             </g>
           </g>
           <g transform="matrix(1 0 0 1 3 4)"><path d="M 0 0 L 1 0" stroke="black" transform="skewX(45) translate(0 1)"/></g>"#,
    ));
    assert_eq!(subs.len(), 2);
    assert_near(subs[0].points[0], v(10.0, -5.0), 1e-6);
    assert_near(subs[0].points[1], v(10.0, -7.0), 1e-6);
    // skewX(45): x += y; the translate(0 1) inside first.
    assert_near(subs[1].points[0], v(4.0, -5.0), 1e-6);
    assert_near(subs[1].points[1], v(5.0, -5.0), 1e-6);
}

#[test]
fn use_instances_each_give_a_subpath() {
    let subs = import(&doc(
        MM,
        r##"<defs><path id="seg" d="M 0 0 L 10 0" stroke="black"/></defs>
           <use href="#seg" x="5" y="5"/>
           <use xlink:href="#seg" transform="translate(0,20)"/>"##,
    ));
    assert_eq!(subs.len(), 2, "the definition itself is not drawn");
    let expect = [
        [v(5.0, -5.0), v(15.0, -5.0)],
        [v(0.0, -20.0), v(10.0, -20.0)],
    ];
    for (s, e) in subs.iter().zip(expect) {
        assert_eq!(s.points.len(), 2);
        assert_near(s.points[0], e[0], 1e-5);
        assert_near(s.points[1], e[1], 1e-5);
    }
    assert!(subs.iter().all(|s| s.source == "seg"));
}

#[test]
fn use_of_a_circle_keeps_exact_geometry_and_its_name() {
    let subs = import(&doc(
        MM,
        r##"<defs><circle id="dot" r="5" stroke="black" fill="none"/></defs>
            <use href="#dot" x="50" y="50"/>
            <g transform="translate(10 0)"><use href="#dot" x="20" y="20"/></g>"##,
    ));
    assert_eq!(subs.len(), 2);
    for (s, c) in subs.iter().zip([v(50.0, -50.0), v(30.0, -20.0)]) {
        assert_eq!(s.source, "dot");
        assert!(s.corner.iter().all(|&k| !k));
        for p in &s.points {
            assert!((p.distance(c) - 5.0).abs() < 1e-4, "{p}");
        }
    }
}

#[test]
fn markers_are_not_printed() {
    let import = match import_svg_with_notes(
        doc(
            MM,
            r##"<defs><marker id="arrow" markerWidth="4" markerHeight="4" refX="2" refY="2">
                  <path d="M 0 0 L 4 2 L 0 4 z"/></marker></defs>
                <path d="M 10 10 L 50 10" stroke="black" marker-end="url(#arrow)"/>"##,
        )
        .as_bytes(),
        "m.svg",
    ) {
        Ok(i) => i,
        Err(e) => panic!("{e}"),
    };
    assert_eq!(import.subpaths.len(), 1);
    assert_eq!(import.subpaths[0].points.len(), 2);
    assert!(import.notes.iter().any(|n| n.contains("marker")));
}

#[test]
fn physical_units_become_mm() {
    let cases = [
        (r#"width="1in" height="1in" viewBox="0 0 1 1""#, 1.0, 25.4),
        (r#"width="2cm" height="2cm" viewBox="0 0 2 2""#, 1.0, 10.0),
        (
            r#"width="72pt" height="72pt" viewBox="0 0 72 72""#,
            72.0,
            25.4,
        ),
        (r#"width="96px" height="96px""#, 96.0, 25.4),
        (r#"width="96" height="96""#, 48.0, 12.7),
        (
            r#"width="80mm" height="40mm" viewBox="0 0 160 80""#,
            10.0,
            5.0,
        ),
    ];
    for (size, len, mm) in cases {
        let subs = import(&doc(
            size,
            &format!(r#"<path d="M 0 0 L {len} 0" stroke="black"/>"#),
        ));
        assert!(
            (subs[0].length_mm() - mm).abs() < 1e-6,
            "{size}: {} mm",
            subs[0].length_mm()
        );
    }
}

#[test]
fn unpainted_and_hidden_elements_are_not_printed() {
    let subs = import(&doc(
        MM,
        r#"<path d="M 0 0 L 10 0" stroke="none" fill="none"/>
           <path d="M 0 0 L 10 0" style="stroke:none;fill:none"/>
           <path d="M 0 0 L 10 0" stroke="black" display="none"/>
           <g style="display:none"><path d="M 0 0 L 10 0" stroke="black"/></g>
           <path d="M 0 0 L 10 0" stroke="black" visibility="hidden"/>
           <rect id="filled" x="1" y="1" width="2" height="2"/>"#,
    ));
    assert_eq!(subs.len(), 1, "{subs:?}");
    assert_eq!(
        subs[0].source, "filled",
        "fill-only (the default black) is kept"
    );
    assert_eq!(subs[0].points.len(), 5);
}

#[test]
fn the_note_on_shapes_not_printed_counts_them_and_names_the_first() {
    let (subs, notes) = notes_of(&doc(
        MM,
        r#"<path d="M 0 0 L 10 0" stroke="black" display="none"/>
           <path id="ghost" d="M 0 0 L 10 0" stroke="black" visibility="hidden"/>
           <path d="M 0 0 L 10 0" stroke="none" fill="none"/>
           <path id="kept" d="M 0 5 L 10 5" stroke="black"/>"#,
    ));
    assert_eq!(subs.len(), 1, "{subs:?}");
    let note = notes
        .iter()
        .find(|n| n.contains("were not printed"))
        .unwrap_or_else(|| panic!("no note on the hidden shapes: {notes:?}"));
    // `display: none` draws nothing and is left out without a word, as
    // SVG viewers leave it out; the hidden and the unpainted are counted.
    assert!(
        note.starts_with("2 shape(s)") && note.contains("(the first: 'ghost')"),
        "{note}"
    );
}

#[test]
fn nothing_printable_is_an_error_that_names_the_file() {
    let text = doc(
        MM,
        r#"<path d="M 0 0 L 10 0" fill="none"/><text x="1" y="1">hello</text>"#,
    );
    match import_svg(text.as_bytes(), "empty.svg") {
        Err(e @ SvgError::NothingPrintable { .. }) => {
            let msg = e.to_string();
            assert!(msg.contains("empty.svg") && msg.contains("text"), "{msg}");
        }
        other => panic!("expected NothingPrintable, got {other:?}"),
    }
}

#[test]
fn inkscape_file_with_layers_styles_and_text() {
    let import = match import_svg_with_notes(include_bytes!("data/svg/inkscape.svg"), "ink.svg") {
        Ok(i) => i,
        Err(e) => panic!("{e}"),
    };
    let subs = &import.subpaths;
    assert_eq!(sources(subs), ["loop", "ring", "half", "pad"]);
    // The layer's translate(-10,-20), then y flipped.
    let expect = [
        v(10.0, -10.0),
        v(40.0, -10.0),
        v(40.0, -30.0),
        v(10.0, -30.0),
    ];
    assert_eq!(subs[0].points.len(), 5);
    for (p, e) in subs[0].points.iter().zip(expect) {
        assert_near(*p, e, 1e-5);
    }
    for p in &subs[1].points {
        assert!((p.distance(v(50.0, -30.0)) - 8.0).abs() < 1e-4);
    }
    // Two arcs, one smooth join: corners only at the ends.
    assert_eq!(corner_points(&subs[2]).len(), 2);
    assert!(!subs[2].closed);
    assert!(
        import.notes.iter().any(|n| n.contains("text")),
        "{:?}",
        import.notes
    );
}

#[test]
fn illustrator_file_with_entities_and_css_classes() {
    let subs = match import_svg(include_bytes!("data/svg/illustrator.svg"), "ai.svg") {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    };
    // The unstroked, unfillable line is dropped.
    assert_eq!(subs.len(), 2);
    let unit = 25.4 / 72.0; // 72pt wide, viewBox 72 units
    assert_near(subs[0].points[1], v(30.0, -10.0) * unit, 1e-5);
    assert!(!subs[0].closed && subs[1].closed);
    assert_eq!(subs[1].points.len(), 4);
}

#[test]
fn missing_xmlns_and_duplicate_ids_are_tolerated() {
    let text = r#"<svg width="10mm" height="10mm" viewBox="0 0 10 10">
        <path id="a" d="M 0 0 L 1 0" stroke="black"/>
        <path id="a" d="M 0 5 A 2 2 0 0 1 4 5" stroke="black"/></svg>"#;
    let subs = import(text);
    assert_eq!(subs.len(), 2);
    assert_eq!(subs[0].points.len(), 2);
    for p in &subs[1].points {
        assert!((p.distance(v(2.0, -5.0)) - 2.0).abs() < 1e-4);
    }
}

// ------------------------------------------------------------- hostile

#[test]
fn hostile_inputs_are_errors_not_panics() {
    let deep = format!(
        "{}{}{}",
        doc(MM, "").replace("</svg>", ""),
        "<g>".repeat(5000),
        "</g>".repeat(5000) + "</svg>"
    );
    let nan_circle = doc(MM, r#"<circle r="NaN" cx="1" cy="1" stroke="black"/>"#);
    let bad_bytes: &[&[u8]] = &[
        b"",
        b"not xml at all",
        b"\xff\xfe\x00<",
        b"<html><body/></html>",
        b"<svg xmlns='http://example.com/not-svg'/>",
        b"<svg xmlns='http://www.w3.org/2000/svg'>",
        b"\x1f\x8b\x08\x00",
        deep.as_bytes(),
        nan_circle.as_bytes(),
    ];
    for bytes in bad_bytes {
        match import_svg(bytes, "bad.svg") {
            Err(e) => assert!(e.to_string().starts_with("bad.svg: "), "{e}"),
            Ok(s) => panic!(
                "expected an error for {:?}, got {s:?}",
                String::from_utf8_lossy(bytes)
            ),
        }
    }
}

#[test]
fn hostile_numbers_give_an_error_or_a_sane_result() {
    let cases = [
        r#"<circle r="1e30" stroke="black"/>"#,
        r#"<circle r="1e38" cx="1e38" stroke="black"/>"#,
        r#"<path d="M 0 0 L 1e38 1e38 L -1e38 3" stroke="black"/>"#,
        r#"<path d="M 0 0 C 1e300 0 0 1e300 1 1" stroke="black"/>"#,
        r#"<path d="M NaN 0 L 1 1" stroke="black"/>"#,
        r#"<path d="M 0 0 L 1 1 L inf 2" stroke="black"/>"#,
        r#"<path d="M 0 0 A 1e-300 1e300 45 1 1 1 1" stroke="black"/>"#,
        r#"<path d="M 0 0 A 0 5 0 0 1 10 0 A 5 5 0 0 1 10 0" stroke="black"/>"#,
        r#"<g transform="scale(1e-30)"><path d="M 0 0 L 1 1" stroke="black"/></g>"#,
        r#"<g transform="matrix(NaN 0 0 1 0 0)"><path d="M 0 0 L 1 1" stroke="black"/></g>"#,
        r#"<rect width="1e30" height="1" rx="1e29" stroke="black"/>"#,
        r##"<use href="#u"/><g id="u"><use href="#u"/></g>"##,
        r#"<path d="M 5 5 L 5 5" stroke="black" stroke-linecap="round"/>"#,
    ];
    for body in cases {
        match import_svg(doc(MM, body).as_bytes(), "h.svg") {
            Err(e) => assert!(e.to_string().starts_with("h.svg: "), "{e}"),
            Ok(subs) => {
                for s in subs {
                    assert!(!s.points.is_empty() && s.points.len() == s.corner.len());
                    assert!(s.points.iter().all(|p| p.is_finite()), "{body}: {s:?}");
                }
            }
        }
    }
}

#[test]
fn use_chains_and_use_bombs_do_not_hang_or_overflow() {
    // A chain of 400 uses, each instantiating the previous one.
    let mut chain = String::from(r#"<defs><path id="g0" d="M 0 0 L 1 0" stroke="black"/>"#);
    for k in 1..400 {
        chain.push_str(&format!(r##"<g id="g{k}"><use href="#g{}"/></g>"##, k - 1));
    }
    chain.push_str(r##"</defs><use href="#g399"/>"##);
    // Each level doubles: 2^40 paths if nothing stopped it.
    let mut bomb = String::from(r#"<defs><path id="b0" d="M 0 0 L 1 0" stroke="black"/>"#);
    for k in 1..40 {
        bomb.push_str(&format!(
            r##"<g id="b{k}"><use href="#b{0}"/><use href="#b{0}"/></g>"##,
            k - 1
        ));
    }
    bomb.push_str(r##"</defs><use href="#b39"/>"##);
    for body in [chain, bomb] {
        let start = std::time::Instant::now();
        let result = import_svg(doc(MM, &body).as_bytes(), "u.svg");
        assert!(start.elapsed().as_secs() < 20, "took {:?}", start.elapsed());
        if let Ok(subs) = result {
            assert!(subs.iter().all(|s| s.points.iter().all(|p| p.is_finite())));
        }
    }
}

#[test]
fn moderately_nested_groups_still_work() {
    let subs = import(&doc(
        MM,
        &format!(
            "{}<path d='M 0 0 L 1 0' stroke='black'/>{}",
            "<g transform='translate(1 0)'>".repeat(100),
            "</g>".repeat(100)
        ),
    ));
    assert_near(subs[0].points[0], v(100.0, 0.0), 1e-4);
}

// ------------------------------------------------------------ placement

#[test]
fn placement_rotates_scales_then_offsets() {
    let p = Placement {
        offset_mm: v(10.0, 20.0),
        rotation_deg: 90.0,
        scale: 2.0,
    };
    assert!(p.validate().is_ok());
    assert_near(p.apply(v(1.0, 0.0)), v(10.0, 22.0), 1e-12);
    assert_eq!(Placement::IDENTITY.apply(v(3.0, -4.0)), v(3.0, -4.0));
    for bad in [
        Placement { scale: 0.0, ..p },
        Placement { scale: -1.0, ..p },
        Placement {
            scale: f64::NAN,
            ..p
        },
        Placement {
            rotation_deg: f64::INFINITY,
            ..p
        },
        Placement {
            offset_mm: v(f64::NAN, 0.0),
            ..p
        },
    ] {
        match bad.validate() {
            Err(e @ SvgError::Placement { .. }) => assert!(e.to_string().contains("placement")),
            other => panic!("expected an error for {bad:?}, got {other:?}"),
        }
    }
}

// -------------------------------------------------------------- sampling

fn intervals(points: &[DVec2]) -> Vec<f64> {
    points.windows(2).map(|w| w[0].distance(w[1])).collect()
}

#[test]
fn sampling_keeps_corners_and_spacing() {
    let subs = import(&doc(
        MM,
        r#"<polyline points="0,0 10,0 10,7.3 3,7.3" stroke="black" fill="none"/>"#,
    ));
    let s = &subs[0];
    let max = 0.3015;
    let out = sample_subpath(s, max);
    assert!(intervals(&out).iter().all(|&d| d <= max + 1e-12));
    for c in corner_points(s) {
        assert!(out.contains(&c), "corner {c} missing");
    }
    // Each straight piece is uniform.
    let marked = match try_sample_subpath_marked(s, max) {
        Ok(m) => m,
        Err(e) => panic!("{e}"),
    };
    let idx: Vec<usize> = (0..marked.points.len())
        .filter(|&i| marked.corner[i])
        .collect();
    assert_eq!(idx.len(), 4);
    for w in idx.windows(2) {
        let d = intervals(&marked.points[w[0]..=w[1]]);
        let (lo, hi) = d
            .iter()
            .fold((f64::MAX, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
        assert!(hi / lo - 1.0 < 1e-6, "{lo} .. {hi}");
    }
    let sampled: f64 = intervals(&out).iter().sum();
    assert!((sampled - s.length_mm()).abs() < 1e-9);
    assert_eq!(out.len(), 1 + 34 + 25 + 24); // ceil(10/.3015), ceil(7.3/.3015), ceil(7/.3015)
}

#[test]
fn sampling_a_circle_is_uniform_and_closed() {
    let subs = import(&doc(
        MM,
        r#"<circle cx="0" cy="0" r="5" stroke="black" fill="none"/>"#,
    ));
    let out = sample_subpath(&subs[0], 0.3);
    assert_eq!(out.first(), out.last());
    let d = intervals(&out);
    let (lo, hi) = d
        .iter()
        .fold((f64::MAX, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
    assert!(hi <= 0.3 && hi / lo - 1.0 < 1e-3);
    assert_eq!(
        out.len(),
        1 + (std::f64::consts::TAU * 5.0 / 0.3).ceil() as usize
    );
}

// -------------------------------------------------------------- antennas

#[test]
fn paper_spiral_is_556_mm_and_1853_points() {
    let subs = import(&paper_spiral_svg());
    assert_eq!(subs.len(), 1);
    let len = subs[0].length_mm();
    assert!((len - PAPER_SPIRAL_LENGTH_MM).abs() < 2.0, "{len}");
    let n = sample_subpath(&subs[0], 0.603 / 2.0).len();
    assert!((n as i64 - 1853).abs() <= 10, "{n} points");
    assert_eq!(corner_points(&subs[0]).len(), 2, "smooth: only its ends");
}

#[test]
fn archimedean_spiral_round_trips() {
    let svg = match archimedean_spiral_svg(3.0, 2.0, 1.0) {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    };
    let subs = import(&svg);
    let expected = pcpp::demo::antennas::archimedean_spiral_length_mm(3.0, 2.0, 1.0);
    let len = subs[0].length_mm();
    // Shorter than the true spiral by the flattening's chord error only.
    assert!((len - expected).abs() < 1e-3, "{len} vs {expected}");
    // Starts at the inner radius on +x of the centre, which sits in the
    // middle of the page, and ends at inner + 3 pitches.
    let half = 1.0 + 3.0 * 2.0 + 2.0 * 0.603;
    let centre = v(half, -half);
    assert_near(subs[0].points[0], centre + v(1.0, 0.0), 1e-5);
    let last = subs[0].points.last().copied().unwrap_or(DVec2::NAN);
    assert!((last.distance(centre) - 7.0).abs() < 1e-5);
    // Counter-clockwise in the printer frame (y up): it starts going +y.
    assert!(subs[0].points[1].y > subs[0].points[0].y);
}

fn segments_cross(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let orient = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
    let eps = 1e-9;
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    if ((d1 > eps && d2 < -eps) || (d1 < -eps && d2 > eps))
        && ((d3 > eps && d4 < -eps) || (d3 < -eps && d4 > eps))
    {
        return true;
    }
    // Touching or overlapping: an end point on the other segment.
    let on = |p: DVec2, q: DVec2, r: DVec2| {
        orient(p, q, r).abs() <= eps
            && r.x >= p.x.min(q.x) - eps
            && r.x <= p.x.max(q.x) + eps
            && r.y >= p.y.min(q.y) - eps
            && r.y <= p.y.max(q.y) + eps
    };
    on(c, d, a) || on(c, d, b) || on(a, b, c) || on(a, b, d)
}

#[test]
fn hilbert_loops_are_closed_simple_and_inside_their_square() {
    for order in 1..=5 {
        let size = 20.0;
        let svg = match hilbert_loop_svg(order, size) {
            Ok(s) => s,
            Err(e) => panic!("{e}"),
        };
        let subs = import(&svg);
        assert_eq!(subs.len(), 1);
        let s = &subs[0];
        assert!(s.closed && s.points.first() == s.points.last());
        let centre = v(size / 2.0 + 0.603, -(size / 2.0 + 0.603));
        assert!(s
            .points
            .iter()
            .all(|p| (*p - centre).abs().max_element() <= size / 2.0));
        let cell = size / f64::from(1u32 << order);
        let expected = cell * f64::from(1u32 << (2 * order));
        let len = s.length_mm();
        assert!(
            (len - expected).abs() < 1e-5 * expected,
            "order {order}: {len} vs {expected}"
        );
        let p = &s.points;
        let n = p.len() - 1;
        for i in 0..n {
            for j in i + 1..n {
                let adjacent = j == i + 1 || (i == 0 && j == n - 1);
                if !adjacent {
                    assert!(
                        !segments_cross(p[i], p[i + 1], p[j], p[j + 1]),
                        "order {order}: segments {i} and {j} meet"
                    );
                }
            }
        }
    }
}

#[test]
fn triangular_monopole_round_trips() {
    let svg = match triangular_monopole_svg(30.0, 20.0, 5.0) {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    };
    let subs = import(&svg);
    assert_eq!(subs.len(), 2);
    let (feed, tri) = (&subs[0], &subs[1]);
    // The apex sits a margin of 2 x 0.603 mm inside the page's corner region.
    let apex = v(10.0 + 1.206, -(30.0 + 1.206));
    assert_near(feed.points[0], apex, 1e-5);
    assert_near(feed.points[1], apex + v(0.0, -5.0), 1e-5);
    assert!(tri.closed);
    assert_eq!(tri.points.len(), 4);
    assert_eq!(tri.corner, vec![true; 4]);
    assert_near(tri.points[0], apex, 1e-5);
    assert_near(tri.points[1], apex + v(-10.0, 30.0), 1e-5);
    assert!(hilbert_loop_svg(0, 1.0).is_err());
    assert!(triangular_monopole_svg(f64::NAN, 1.0, 1.0).is_err());
}

// ---------------------------------------------------------------------------
// Limits (README "Limits"): each ends in a message that says what to check.
// ---------------------------------------------------------------------------

#[test]
fn nesting_past_the_limit_is_refused_with_its_depth() {
    let depth = pcpp::svg::MAX_NESTING_DEPTH + 5;
    let body = format!(
        "{}<path d=\"M0 0 L10 10\" stroke=\"black\"/>{}",
        "<g>".repeat(depth),
        "</g>".repeat(depth)
    );
    let e = import_svg(doc(MM, &body).as_bytes(), "deep.svg")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("deep.svg") && e.contains("nested more than 128 levels"),
        "{e}"
    );
    // At the limit it still imports.
    let ok = pcpp::svg::MAX_NESTING_DEPTH - 2;
    let body = format!(
        "{}<path d=\"M0 0 L10 10\" stroke=\"black\"/>{}",
        "<g>".repeat(ok),
        "</g>".repeat(ok)
    );
    assert_eq!(import(&doc(MM, &body)).len(), 1);
}

#[test]
fn a_drawing_needing_too_many_points_names_the_limit_and_the_units() {
    // Five circles of 9 km radius (under the 1e7 coordinate guard) need about
    // 950,000 points each at the 5e-5 mm flattening tolerance.
    let body: String = (0..5)
        .map(|k| {
            format!(
                "<circle cx=\"{}\" cy=\"0\" r=\"9e6\" stroke=\"black\" fill=\"none\"/>",
                k
            )
        })
        .collect();
    let e = import_svg(doc(MM, &body).as_bytes(), "huge.svg")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("huge.svg")
            && e.contains("more than 4000000 points")
            && e.contains("counted over all its shapes")
            && e.contains("shape 5 as drawn")
            && e.contains("units"),
        "{e}"
    );
}

#[test]
fn a_path_needing_too_many_samples_names_the_count_and_the_units() {
    // A 9 km line at d/2 = 0.3 mm spacing: 30 M samples, past MAX_SAMPLES.
    let subs = import(&doc(
        MM,
        r#"<path id="long" d="M0 0 L9000000 0" stroke="black"/>"#,
    ));
    let e = try_sample_subpath_marked(&subs[0], 0.3)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("samples needed at 0.3 mm spacing, more than 10000000")
            && e.contains("check the drawing's units"),
        "{e}"
    );
}

// ---------------------------------------------------------------------------
// What exploratory QA found changed silently (each now printed as drawn, or
// told): dashes, path-data errors, icon sprites, the root's size.
// ---------------------------------------------------------------------------

/// The notes of a drawing that imports.
fn notes_of(text: &str) -> (Vec<Subpath2>, Vec<String>) {
    match import_svg_with_notes(text.as_bytes(), "qa.svg") {
        Ok(i) => (i.subpaths, i.notes),
        Err(e) => panic!("import failed: {e}\n{text}"),
    }
}

/// The one note that contains `word`.
/// The element each subpath comes from, in order.
fn sources(subs: &[Subpath2]) -> Vec<&str> {
    subs.iter().map(|s| s.source.as_str()).collect()
}

/// Asserts that no note contains `word`.
fn no_note_with(notes: &[String], word: &str) {
    assert!(
        notes.iter().all(|n| !n.contains(word)),
        "no note with {word:?}: {notes:?}"
    );
}

fn note_with<'a>(notes: &'a [String], word: &str) -> &'a str {
    let found: Vec<&String> = notes.iter().filter(|n| n.contains(word)).collect();
    assert_eq!(found.len(), 1, "one note with {word:?}: {notes:?}");
    found[0]
}

fn import_error(text: &str) -> String {
    match import_svg(text.as_bytes(), "qa.svg") {
        Ok(s) => panic!("expected an error, read {s:?}"),
        Err(e) => e.to_string(),
    }
}

const PAGE_40: &str = r#"width="40mm" height="20mm" viewBox="0 0 40 20""#;

/// QA `dash.svg`: a 36 mm line with `stroke-dasharray="4 2"` was printed as
/// one solid line. SVG draws six 4 mm dashes, each now its own piece, and a
/// note says so; `stroke-dashoffset` shifts them as SVG shifts them.
#[test]
fn dashed_stroke_printed_solid() {
    let (subs, notes) = notes_of(&doc(
        PAGE_40,
        r#"<path id="trace" d="M2,10 H38" stroke="black" stroke-dasharray="4 2" fill="none"/>"#,
    ));
    assert_eq!(subs.len(), 6, "{subs:?}");
    for (k, s) in subs.iter().enumerate() {
        let x0 = 2.0 + 6.0 * k as f64;
        assert_eq!(s.points.len(), 2, "{s:?}");
        assert_near(s.points[0], v(x0, -10.0), 1e-5);
        assert_near(s.points[1], v(x0 + 4.0, -10.0), 1e-5);
        assert_eq!(s.corner, vec![true, true]);
        assert!(!s.closed);
        assert_eq!(s.source, "trace");
    }
    let note = note_with(&notes, "dash");
    assert!(
        note.starts_with("1 shape(s)")
            && note.contains("'trace'")
            && note.contains("6 pieces")
            && note.contains("its own piece")
            && note.contains("stroke-dasharray"),
        "{note}"
    );

    // An offset of 1 starts the pattern 1 unit in: a first dash of 3, and a
    // last of 1 cut by the end of the line.
    let (subs, _) = notes_of(&doc(
        PAGE_40,
        r#"<path d="M2,10 H38" stroke="black" stroke-dasharray="4 2" stroke-dashoffset="1"/>"#,
    ));
    let spans: Vec<(f64, f64)> = subs
        .iter()
        .map(|s| (s.points[0].x, s.points[s.points.len() - 1].x))
        .collect();
    let want = [
        (2.0, 5.0),
        (7.0, 11.0),
        (13.0, 17.0),
        (19.0, 23.0),
        (25.0, 29.0),
        (31.0, 35.0),
        (37.0, 38.0),
    ];
    assert_eq!(spans.len(), want.len(), "{spans:?}");
    for (got, want) in spans.iter().zip(want) {
        assert!(
            (got.0 - want.0).abs() < 1e-5 && (got.1 - want.1).abs() < 1e-5,
            "{spans:?}"
        );
    }
}

/// Dashes keep the drawn corners: a vertex inside a dash keeps its flag (a
/// straight-through vertex is no corner, a right angle is), and a dash's
/// own ends are corners (the ends of an open piece).
#[test]
fn dashes_keep_the_drawn_corners() {
    let (subs, _) = notes_of(&doc(
        MM,
        r#"<path d="M0,0 H5 H10 V10" stroke="black" stroke-dasharray="6 2" fill="none"/>"#,
    ));
    // Dashes over [0, 6] and [8, 14] of the 20-unit path, then [16, 20].
    assert_eq!(subs.len(), 3, "{subs:?}");
    assert_eq!(subs[0].points.len(), 3);
    assert_near(subs[0].points[1], v(5.0, 0.0), 1e-5);
    assert_eq!(subs[0].corner, vec![true, false, true]);
    assert_eq!(subs[1].points.len(), 3);
    assert_near(subs[1].points[1], v(10.0, 0.0), 1e-5);
    assert_eq!(subs[1].corner, vec![true, true, true]);
    assert_near(subs[2].points[0], v(10.0, -6.0), 1e-5);
}

/// A dashed closed shape as SVG draws it: the first dash is left for the
/// end, where it continues the last one through the start point (one
/// piece, no corner at the start of a smooth circle).
#[test]
fn a_dashed_circle_joins_its_last_dash_to_its_first() {
    let (subs, _) = notes_of(&doc(
        MM,
        r#"<circle cx="30" cy="20" r="5" stroke="black" stroke-dasharray="5 5" fill="none"/>"#,
    ));
    // Circumference 31.42: dashes over [10, 15], [20, 25] and [30, 36.42].
    let tau = std::f64::consts::TAU;
    assert_eq!(subs.len(), 3, "{subs:?}");
    let lengths: Vec<f64> = subs.iter().map(|s| s.length_mm()).collect();
    for (got, want) in lengths.iter().zip([5.0, 5.0, 5.0 + tau * 5.0 - 30.0]) {
        assert!((got - want).abs() < 1e-3, "{lengths:?}");
    }
    for s in &subs {
        assert!(!s.closed);
        assert!(s.corner[0] && s.corner[s.corner.len() - 1]);
        assert!(s.corner[1..s.corner.len() - 1].iter().all(|&c| !c), "{s:?}");
        for p in &s.points {
            assert!((p.distance(v(30.0, -20.0)) - 5.0).abs() < 1e-4, "{p}");
        }
    }
    // The joined piece passes through the circle's start, (35, -20).
    assert!(subs[2]
        .points
        .iter()
        .any(|p| p.distance(v(35.0, -20.0)) < 1e-5));
}

/// Patterns that draw no dashes print the stroke solid, with a note naming
/// the shape and its pattern: zero total length and a negative length
/// (which SVG draws solid), and only zero-length dashes (dots).
#[test]
fn degenerate_dash_patterns_print_solid_with_a_note() {
    for (pattern, why) in [
        ("0 0", "solid"),
        ("-1 2", "negative"),
        ("0 3", "zero length"),
    ] {
        let (subs, notes) = notes_of(&doc(
            PAGE_40,
            &format!(r#"<path id="d" d="M2,10 H38" stroke="black" stroke-dasharray="{pattern}"/>"#),
        ));
        assert_eq!(subs.len(), 1, "{pattern}: {subs:?}");
        assert!((subs[0].length_mm() - 36.0).abs() < 1e-5);
        let note = note_with(&notes, "solid");
        assert!(
            note.contains("'d'") && note.contains(pattern) && note.contains(why),
            "{pattern}: {note}"
        );
    }
    // From a `style` attribute on a group, as Inkscape writes it.
    let (subs, notes) = notes_of(&doc(
        PAGE_40,
        r#"<g style="stroke-dasharray:0,0"><path d="M2,10 H38" stroke="black"/></g>"#,
    ));
    assert_eq!(subs.len(), 1);
    assert!(note_with(&notes, "solid").contains("path #1"), "{notes:?}");
    // `none` is no dash pattern at all: no note.
    let (_, notes) = notes_of(&doc(
        PAGE_40,
        r#"<path d="M2,10 H38" stroke="black" style="stroke-dasharray:none"/>"#,
    ));
    assert!(notes.is_empty(), "{notes:?}");
}

/// QA `nan2.svg`: `L NaN 5` ended the path there without a word (18 of its
/// 36 mm printed). SVG draws up to the error, so the same part is printed,
/// and a note names the element, the character and the text there.
#[test]
fn path_data_error_truncates_the_path_silently() {
    let (subs, notes) = notes_of(&doc(
        PAGE_40,
        r#"<path d="M2,10 L20,10 L NaN 5 L38,10" stroke="black" fill="none"/>"#,
    ));
    assert_eq!(subs.len(), 1);
    assert!((subs[0].length_mm() - 18.0).abs() < 1e-5);
    let note = note_with(&notes, "error");
    assert!(
        note.contains("'path #1'")
            && note.contains("character 16")
            && note.contains("NaN 5 L38,10")
            && note.contains("path data"),
        "{note}"
    );
}

/// QA `nan2.svg` with the error first: the import said "the document
/// contains no shapes", hiding the cause. It now names the path's error.
#[test]
fn path_data_error_before_anything_is_drawn_is_named_in_the_error() {
    let e = import_error(&doc(
        PAGE_40,
        r#"<path id="trace" d="M2,10 L NaN 5 L38,10" stroke="black" fill="none"/>"#,
    ));
    assert!(
        e.contains("nothing printable")
            && e.contains("'trace'")
            && e.contains("character 9")
            && e.contains("NaN 5")
            && !e.contains("contains no shapes"),
        "{e}"
    );
}

/// QA `typo.svg`: `L25,,5` was read as `L25,5` by the f64 re-reading
/// (39.2 mm printed) while usvg, and browsers, stop at the second comma
/// (SVG allows one between numbers). The print now stops where the drawing
/// does, with the note.
#[test]
fn double_comma_in_path_data_read_unlike_svg() {
    let (subs, notes) = notes_of(&doc(
        PAGE_40,
        r#"<path d="M2,10 L20,10 L25,,5 L38,10" stroke="black" fill="none"/>"#,
    ));
    assert_eq!(subs.len(), 1);
    assert!((subs[0].length_mm() - 18.0).abs() < 1e-5, "{subs:?}");
    let note = note_with(&notes, "error");
    assert!(
        note.contains("character 18") && note.contains("two commas"),
        "{note}"
    );
}

/// A `<polyline>` whose `points` hold a word (`10,x`) was printed up to it
/// without a word: 2 of its 5 points. SVG draws up to the error, so the same
/// part is printed, and a note names the file, the element, the character,
/// the word and the points kept.
#[test]
fn polyline_points_error_truncated_silently() {
    let (subs, notes) = notes_of(&doc(
        PAGE_40,
        r#"<polyline points="0,0 10,0 10,x 20,20 30,30" stroke="black" fill="none"/>"#,
    ));
    assert_eq!(subs.len(), 1);
    assert_eq!(subs[0].points.len(), 2, "{subs:?}");
    assert_near(subs[0].points[1], v(10.0, 0.0), 1e-5);
    let note = note_with(&notes, "points");
    assert!(
        note.starts_with("1 polyline/polygon(s) in qa.svg ")
            && note.contains("'polyline #1' at character 13: 'x' is not a number; 2 points kept"),
        "{note}"
    );
}

/// `points="0,0 10,0 10,10 20"`: the lone 20 (an x with no y) was dropped
/// without a word. It still is, as SVG drops it, with a note giving the odd
/// count and the points kept; an id names the element with its kind.
#[test]
fn odd_coordinate_count_in_points_dropped_silently() {
    let (subs, notes) = notes_of(&doc(
        PAGE_40,
        r#"<polygon id="tri" points="0,0 10,0 10,10 20" stroke="black" fill="none"/>"#,
    ));
    assert_eq!(subs.len(), 1);
    assert!(subs[0].closed);
    assert_eq!(subs[0].points.len(), 4, "{subs:?}");
    let note = note_with(&notes, "points");
    assert!(
        note.contains("polygon 'tri': 7 numbers, an odd count (the last, 20, is an x with no y); 3 points kept"),
        "{note}"
    );
}

/// `points` that leave fewer than 2 points draw nothing: beside another
/// shape the element vanished without a word; alone, the error said the
/// document "contains no shapes". Both now say why, once per element, and
/// the error names the file once.
#[test]
fn points_too_few_to_draw_are_named() {
    let cases = [
        // Said as what it is: "printed up to its last whole x,y pair"
        // does not apply to nothing.
        ("", "have no points ('polyline #1'): not printed"),
        ("  ", "have no points ('polyline #1'): not printed"),
        ("5,5", "'polyline #1': only 1 point (5, 5); 2 are needed to draw: not printed"),
        ("a,b", "'polyline #1' at character 1: 'a' is not a number; no point kept: not printed"),
        ("1,2 3", "'polyline #1': 3 numbers, an odd count (the last, 3, is an x with no y); 1 point kept, 2 are needed to draw: not printed"),
        ("1,2,,3,4", "'polyline #1' at character 5: two commas in a row (SVG allows one between numbers); 1 point kept, 2 are needed to draw: not printed"),
    ];
    for (points, expected) in cases {
        let alone = format!(r#"<polyline points="{points}" stroke="black" fill="none"/>"#);
        let e = import_error(&doc(PAGE_40, &alone));
        assert!(
            e.starts_with("qa.svg: nothing printable: no shape is left to draw (1 polyline")
                && e.contains(expected)
                && e.matches("qa.svg").count() == 1,
            "{points:?}: {e}"
        );
        let beside = format!(r#"{alone}<line x1="0" y1="5" x2="10" y2="5" stroke="black"/>"#);
        let (subs, notes) = notes_of(&doc(PAGE_40, &beside));
        assert_eq!(subs.len(), 1, "{points:?}");
        let note = note_with(&notes, "points");
        assert!(note.contains(expected), "{points:?}: {note}");
    }
}

/// Valid point lists in SVG's number syntax (commas and/or whitespace,
/// signs, exponents, "1.5.5" as 1.5 and .5, "1-2" as 1 and -2, trailing
/// separators) give no note and every point.
#[test]
fn tricky_but_valid_points_get_no_note() {
    let cases: [(&str, &[(f64, f64)]); 7] = [
        ("0,0 10,0 10,10", &[(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)]),
        (
            "0 0,10 0\n\t10\r\n10 ",
            &[(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)],
        ),
        (
            "  0,0,10,0 , 10 , 10,",
            &[(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)],
        ),
        (
            "+1e1-2E-1 1.5.5-.5,20",
            &[(10.0, -0.2), (1.5, 0.5), (-0.5, 20.0)],
        ),
        ("1-2-3-4", &[(1.0, -2.0), (-3.0, -4.0)]),
        (
            "1e+1,2e-0 .5.5 3.,4",
            &[(10.0, 2.0), (0.5, 0.5), (3.0, 4.0)],
        ),
        (
            "0,0 10,0 10,10 ,  ",
            &[(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)],
        ),
    ];
    for (points, expected) in cases {
        let text = doc(
            PAGE_40,
            &format!(r#"<polyline points="{points}" stroke="black" fill="none"/>"#),
        );
        let (subs, mut notes) = notes_of(&text);
        // (One case reaches past the page's edge: that note is not about
        // the points.)
        notes.retain(|n| !n.contains("off the page"));
        assert!(notes.is_empty(), "{points:?}: {notes:?}");
        assert_eq!(subs.len(), 1, "{points:?}");
        let got = &subs[0].points;
        assert_eq!(got.len(), expected.len(), "{points:?}: {got:?}");
        for (&p, &(x, y)) in got.iter().zip(expected) {
            // y up: SVG's y is negated.
            assert_near(p, v(x, -y), 1e-5);
        }
    }
}

/// QA `feather-sprite.svg` (287 `<symbol>`s, no `<use>`): the error said
/// the document contains no shapes. It now says where they are, why they
/// draw nothing, and how to print one.
#[test]
fn icon_sprite_reported_as_containing_no_shapes() {
    let e = import_error(&doc(
        "",
        r#"<defs><symbol id="activity" viewBox="0 0 24 24"><polyline points="22 12 18 12 15 21 9 3 6 12 2 12"></polyline></symbol>
           <symbol id="airplay" viewBox="0 0 24 24"><path d="M5 17H4a2 2 0 0 1-2-2V5"></path><polygon points="12 15 17 21 7 21 12 15"></polygon></symbol>
           <symbol id="alert-circle" viewBox="0 0 24 24"><circle cx="12" cy="12" r="10"></circle></symbol>
           <symbol id="anchor" viewBox="0 0 24 24"><circle cx="12" cy="5" r="3"></circle></symbol></defs>"#,
    ));
    assert!(
        e.contains("5 shape(s)")
            && e.contains("4 <symbol>")
            && e.contains("'activity', 'airplay', 'alert-circle'")
            && e.contains("<use")
            && e.contains("href=\"#activity\"")
            && e.contains("sprite")
            && !e.contains("contains no shapes"),
        "{e}"
    );
    // A used symbol is printed as before.
    let subs = import(&doc(
        MM,
        r##"<defs><symbol id="dash"><path d="M0 0 H10" stroke="black"/></symbol></defs><use href="#dash"/>"##,
    ));
    assert_eq!(subs.len(), 1);
}

/// QA round 18 F10: ionicons' sprite sheet hides its root
/// (`style="display:none"`); told to add a <use>, the user did, and was
/// told "none does" again. The hidden root is named, and how to mend it.
#[test]
fn a_hidden_root_is_named_not_the_missing_use() {
    let symbols =
        r##"<defs><symbol id="dash"><path d="M0 0 H10" stroke="black"/></symbol></defs>"##;
    for (root, how) in [
        (r#"style="display:none""#, r#"style="display:none""#),
        (
            r#"style="fill: red; display : none""#,
            r#"style="fill: red; display : none""#,
        ),
        (r#"display="none""#, r#"display="none""#),
    ] {
        for body in [
            symbols.to_string(),
            format!(r##"{symbols}<use href="#dash"/>"##),
        ] {
            let e = import_error(&doc(&format!("{MM} {root}"), &body));
            assert!(
                e.contains(&format!("the root <svg> is hidden ({how})"))
                    && e.contains("remove that from the root <svg>")
                    && !e.contains("none does"),
                "{root} {body}: {e}"
            );
        }
    }
    // Shown, the used symbol prints.
    let subs = import(&doc(MM, &format!(r##"{symbols}<use href="#dash"/>"##)));
    assert_eq!(subs.len(), 1);
}

/// QA `vb0.svg`: `viewBox="0 0 0 0"` was ignored and user units taken as
/// px, printing 9.5 mm where the page is 40 mm wide. SVG draws nothing for a
/// zero-size viewBox (a viewer shows an empty page), and no scale can be
/// trusted, so the import refuses it, naming the attribute and the fix,
/// rather than print at a guessed size.
#[test]
fn zero_viewbox_ignored_silently() {
    for vb in ["0 0 0 0", "0 0 40 0"] {
        let e = import_error(&doc(
            &format!(r#"width="40mm" height="20mm" viewBox="{vb}""#),
            r#"<path d="M2,10 H38" stroke="black"/>"#,
        ));
        assert!(
            e.contains(&format!("viewBox=\"{vb}\"")) && e.contains("zero") && e.contains("remove"),
            "{e}"
        );
    }
}

/// A negative viewBox size is an error that makes SVG ignore the attribute
/// (viewers then draw the content in px), so it is followed, as usvg does,
/// with a note saying what was assumed.
#[test]
fn negative_or_unreadable_viewbox_is_ignored_with_a_note() {
    for vb in ["0 0 -40 20", "0 0 40"] {
        let (subs, notes) = notes_of(&doc(
            &format!(r#"width="40mm" height="20mm" viewBox="{vb}""#),
            r#"<path d="M2,10 H38" stroke="black"/>"#,
        ));
        assert!((subs[0].length_mm() - 36.0 * 25.4 / 96.0).abs() < 1e-5);
        let note = note_with(&notes, "viewBox");
        assert!(
            note.contains(&format!("\"{vb}\"")) && note.contains("ignored") && note.contains("px"),
            "{note}"
        );
    }
}

/// `width="100%"` falls back to the viewBox's size in px: the note says what
/// page size was taken, so a wrong scale is not silent.
#[test]
fn percentage_width_falls_back_to_px_silently() {
    let (subs, notes) = notes_of(&doc(
        r#"width="100%" height="100%" viewBox="0 0 40 20""#,
        r#"<path d="M2,10 H38" stroke="black"/>"#,
    ));
    let px = 25.4 / 96.0;
    assert!((subs[0].length_mm() - 36.0 * px).abs() < 1e-5);
    let note = note_with(&notes, "%");
    assert!(
        note.contains("width=\"100%\"")
            && note.contains("height=\"100%\"")
            && note.contains("10.6 x 5.3 mm")
            && note.contains("mm"),
        "{note}"
    );
}

/// A viewBox with no width or height (icon sets: simple-icons, ionicons)
/// is read at its size in CSS px, as `width="100%"` is, and now said so
/// too (QA round 3: the percentage got a note, the missing size none).
/// One of them given sets the size with the viewBox's aspect: no note.
#[test]
fn a_viewbox_without_a_size_is_read_in_px_and_said() {
    let (subs, notes) = notes_of(&doc(
        r#"viewBox="0 0 40 20""#,
        r#"<path d="M2,10 H38" stroke="black"/>"#,
    ));
    let px = 25.4 / 96.0;
    assert!((subs[0].length_mm() - 36.0 * px).abs() < 1e-5);
    let note = note_with(&notes, "no width or height");
    assert!(
        note.starts_with(
            "the root <svg> gives no width or height: the drawing was read at its \
                          viewBox's size in CSS px (96 per inch) (10.6 x 5.3 mm)"
        ),
        "{note}"
    );
    let (_, notes) = notes_of(&doc(
        r#"width="40mm" viewBox="0 0 40 20""#,
        r#"<path d="M2,10 H38" stroke="black"/>"#,
    ));
    assert!(!notes.iter().any(|n| n.contains("gives no")), "{notes:?}");
}

/// A stroke far wider than a nozzle's trace is printed along its centre
/// line: the note names the widest and its width in mm.
#[test]
fn wide_stroke_printed_as_its_centre_line_silently() {
    let (subs, notes) = notes_of(&doc(
        MM,
        r#"<path id="thin" d="M0,0 H10" stroke="black" stroke-width="0.3"/>
           <path id="wide" d="M0,5 H10" stroke="black" stroke-width="12"/>"#,
    ));
    assert_eq!(subs.len(), 2);
    let note = note_with(&notes, "wide");
    assert!(
        note.contains("'wide'") && note.contains("12.00 mm") && note.contains("centre line"),
        "{note}"
    );
    let (_, notes) = notes_of(&doc(
        MM,
        r#"<path d="M0,0 H10" stroke="black" stroke-width="0.5"/>"#,
    ));
    assert!(notes.is_empty(), "{notes:?}");
}

/// Hostile path data and dash patterns: an error or a sane result, never a
/// panic, a hang or an unbounded allocation.
#[test]
fn hostile_dashes_and_path_data_do_not_panic() {
    let long_garbage = format!("M0 0 L1 1 {}", "\u{e9}\u{1F600},,".repeat(10_000));
    let cases = [
        r#"<path d="M0 0 H90000" stroke="black" stroke-dasharray="1e-30 1e-30"/>"#.to_string(),
        r#"<path d="M0 0 H90000" stroke="black" stroke-dasharray="1e-3"/>"#.to_string(),
        r#"<path d="M0 0 H10" stroke="black" stroke-dasharray="1e38 1e38" stroke-dashoffset="-1e38"/>"#.to_string(),
        r#"<path d="M0 0 H10" stroke="black" stroke-dasharray="1 2" stroke-dashoffset="NaN"/>"#.to_string(),
        r#"<path d="M0 0 H10" stroke="black" stroke-dasharray="3e38 3e38 3e38"/>"#.to_string(),
        r#"<path d="M0 0 H10" stroke="black" stroke-dasharray="1, ,2 x"/>"#.to_string(),
        r#"<path d="M 1e38 0 L -1e38 0" stroke="black" stroke-dasharray="1 1"/>"#.to_string(),
        r#"<path d="M0 0 Z" stroke="black" stroke-dasharray="1 1"/>"#.to_string(),
        r#"<circle r="3" stroke="black" stroke-dasharray="0.000001 100"/>"#.to_string(),
        format!(r#"<path d="{long_garbage}" stroke="black"/>"#),
        r#"<path d="M0 0 L 1 \u{e9} 2" stroke="black"/>"#.to_string(),
        r#"<path d="M0 0 L 1" stroke="black"/>"#.to_string(),
        r#"<path d="Z" stroke="black"/>"#.to_string(),
        r#"<path d=",,," stroke="black"/>"#.to_string(),
        format!(r#"<polyline points="{}x" stroke="black"/>"#, "1,".repeat(50_000)),
        format!(r#"<polygon points="0 0 1 1 {long_garbage}" stroke="black"/>"#),
        r#"<polygon points="\u{e9}" stroke="black"/>"#.to_string(),
        r#"<polyline points="1e38,1e38 -1e38,-1e38 x" stroke="black"/>"#.to_string(),
    ];
    for body in &cases {
        for size in [MM, r#"width="100%" viewBox="0 0 -1 1e-40""#] {
            let start = std::time::Instant::now();
            match import_svg_with_notes(doc(size, body).as_bytes(), "h.svg") {
                Err(e) => assert!(e.to_string().starts_with("h.svg: "), "{e}"),
                Ok(import) => {
                    for s in import.subpaths {
                        assert!(!s.points.is_empty() && s.points.len() == s.corner.len());
                        assert!(s.points.iter().all(|p| p.is_finite()), "{body}: {s:?}");
                    }
                    assert!(
                        import.notes.iter().all(|n| n.len() < 2000),
                        "{:?}",
                        import.notes
                    );
                }
            }
            assert!(
                start.elapsed().as_secs() < 20,
                "{body}: {:?}",
                start.elapsed()
            );
        }
    }
}

// ------------------------------------------------- user units to mm, in f64

/// The drawing of the scale bug: a 32 mm line and its turn, 4 mm in from
/// the corner of a 40 mm page.
const SQUARE: &str = r#"<path d="M4 4 L36 4 L36 36" fill="none" stroke="black"/>"#;

fn square_points(mm_per_unit: f64) -> Vec<DVec2> {
    [(4.0, 4.0), (36.0, 4.0), (36.0, 36.0)]
        .into_iter()
        .map(|(x, y)| v(x * mm_per_unit, -(y * mm_per_unit)))
        .collect()
}

/// usvg holds the document's mm-to-px scale (3.7795276 px/mm) and the
/// viewBox's scale in f32, and every drawing came in 1 + 2.8e-8 times too
/// large (4 and 36 mm as 4.000000111 and 36.000001001): the scale from
/// user units to mm is now f64, so round numbers stay round.
#[test]
fn a_drawing_in_mm_is_not_2_8e_8_too_large() {
    let mm = 1.0;
    let cases = [
        (r#"width="40mm" height="40mm" viewBox="0 0 40 40""#, mm),
        (r#"width="4cm" height="4cm" viewBox="0 0 40 40""#, mm),
        // The height follows the viewBox's aspect.
        (r#"width="40mm" viewBox="0 0 40 40""#, mm),
        (r#"height="40mm" viewBox="0 0 40 40""#, mm),
        (r#"width="20mm" height="20mm" viewBox="0 0 40 40""#, 0.5),
        (
            r#"width="1.5in" height="1.5in" viewBox="0 0 1.5 1.5""#,
            25.4,
        ),
        (
            r#"width="40px" height="40px" viewBox="0 0 40 40""#,
            25.4 / 96.0,
        ),
        (r#"width="40" height="40" viewBox="0 0 40 40""#, 25.4 / 96.0),
        (r#"viewBox="0 0 40 40""#, 25.4 / 96.0),
        (r#"width="40" height="40""#, 25.4 / 96.0),
        (r#"width="40mm" height="40mm""#, 25.4 / 96.0),
        (
            r#"width="72pt" height="72pt" viewBox="0 0 72 72""#,
            25.4 / 72.0,
        ),
        (r#"width="6pc" height="6pc" viewBox="0 0 6 6""#, 25.4 / 6.0),
        (
            r#"width="100%" height="100%" viewBox="0 0 40 40""#,
            25.4 / 96.0,
        ),
    ];
    for (size, mm_per_unit) in cases {
        let subs = import(&doc(size, SQUARE));
        assert_eq!(subs[0].points, square_points(mm_per_unit), "{size}");
    }
    // An inch is 25.4 mm to the last bit.
    let subs = import(&doc(
        r#"width="1.5in" height="1.5in" viewBox="0 0 1.5 1.5""#,
        r#"<path d="M0.25 0.5 L1 0.5" stroke="black"/>"#,
    ));
    assert_eq!(subs[0].points, vec![v(6.35, -12.7), v(25.4, -12.7)]);
}

#[test]
fn a_viewbox_offset_and_its_alignment_are_exact_in_mm() {
    let cases = [
        (
            r#"width="40mm" height="40mm" viewBox="10 -5 40 40""#,
            r#"<path d="M14 -1 L46 -1" stroke="black"/>"#,
            [v(4.0, -4.0), v(36.0, -4.0)],
        ),
        // meet: the 40-unit box scaled by 1 in the middle of the 80 mm.
        (
            r#"width="80mm" height="40mm" viewBox="0 0 40 40""#,
            SQUARE,
            [v(24.0, -4.0), v(56.0, -4.0)],
        ),
        (
            r#"width="80mm" height="40mm" viewBox="0 0 40 40" preserveAspectRatio="xMaxYMax""#,
            SQUARE,
            [v(44.0, -4.0), v(76.0, -4.0)],
        ),
        // slice: scaled by 2, the middle 20 mm of its height cut away.
        (
            r#"width="80mm" height="40mm" viewBox="0 0 40 40" preserveAspectRatio="xMidYMid slice""#,
            SQUARE,
            [v(8.0, 12.0), v(72.0, 12.0)],
        ),
        (
            r#"width="80mm" height="40mm" viewBox="0 0 40 40" preserveAspectRatio="none""#,
            SQUARE,
            [v(8.0, -4.0), v(72.0, -4.0)],
        ),
    ];
    for (size, body, want) in cases {
        let subs = import(&doc(size, body));
        assert_eq!(subs[0].points[..2], want, "{size}");
    }
}

#[test]
fn rects_and_nested_transforms_are_exact_in_mm() {
    let subs = import(&doc(
        r#"width="40mm" height="40mm" viewBox="0 0 40 40""#,
        r#"<rect x="4" y="4" width="32" height="32" stroke="black" fill="none"/>
           <g transform="translate(10 20)"><path transform="scale(2)" d="M1 1 L3 1" stroke="black"/></g>
           <g transform="scale(0.1)"><g><path d="M40 40 L360 40" stroke="black"/></g></g>
           <g transform="matrix(0.26458333,0,0,0.26458333,0,0)"><path d="M0 0 L100 0" stroke="black"/></g>"#,
    ));
    assert_eq!(subs.len(), 4);
    assert_eq!(
        subs[0].points,
        vec![
            v(4.0, -4.0),
            v(36.0, -4.0),
            v(36.0, -36.0),
            v(4.0, -36.0),
            v(4.0, -4.0)
        ]
    );
    assert_eq!(subs[1].points, vec![v(12.0, -22.0), v(16.0, -22.0)]);
    // (0.1 and 0.26458333 are not f32 numbers: usvg's 0.1f32 had put the
    // line at 4.0000000596 mm.)
    assert_eq!(subs[2].points, vec![v(4.0, -4.0), v(36.0, -4.0)]);
    assert_eq!(
        subs[3].points,
        vec![v(0.0, 0.0), v(100.0 * 0.26458333, 0.0)]
    );
}

/// Shapes placed by usvg's own transforms (a `use` instance, a nested
/// `svg`, a transform set in CSS) get the f64 root scale too: only f64's
/// rounding is left, not f32's 2.8e-8.
#[test]
fn uses_nested_svgs_and_css_transforms_get_the_exact_root_scale() {
    let cases = [
        (
            r##"<defs><path id="seg" d="M4 4 L36 4" stroke="black"/></defs><use href="#seg" x="1" y="2"/>"##,
            [v(5.0, -6.0), v(37.0, -6.0)],
        ),
        (
            r#"<svg x="2" y="3" overflow="visible"><path d="M4 4 L36 4" stroke="black"/></svg>"#,
            [v(6.0, -7.0), v(38.0, -7.0)],
        ),
        (
            r#"<style>.moved { transform: translate(1 2) }</style>
               <path class="moved" d="M4 4 L36 4" stroke="black"/>"#,
            [v(5.0, -6.0), v(37.0, -6.0)],
        ),
        (
            r#"<g style="transform: translate(1 2)"><path d="M4 4 L36 4" stroke="black"/></g>"#,
            [v(5.0, -6.0), v(37.0, -6.0)],
        ),
    ];
    for (body, want) in cases {
        let subs = import(&doc(
            r#"width="40mm" height="40mm" viewBox="0 0 40 40""#,
            body,
        ));
        assert_eq!(subs.len(), 1, "{body}");
        for (got, want) in subs[0].points.iter().zip(want) {
            assert_near(*got, want, 1e-12);
        }
    }
}

/// The root's own `transform` (SVG 2) acts in the viewport, in px, about
/// its centre, as usvg applies it.
#[test]
fn a_transform_on_the_root_is_applied_in_f64() {
    let cases = [
        (
            r#"transform="translate(10 0)""#,
            v(4.0 + 10.0 * 25.4 / 96.0, -4.0),
        ),
        // A quarter turn about the page's centre (20, 20) mm.
        (r#"transform="rotate(90)""#, v(36.0, -4.0)),
    ];
    for (transform, want) in cases {
        let size = format!(r#"width="40mm" height="40mm" viewBox="0 0 40 40" {transform}"#);
        let subs = import(&doc(&size, SQUARE));
        assert_near(subs[0].points[0], want, 1e-12);
    }
}

/// `--place centre` of the 40 mm drawing on the demo part (80 x 80 mm)
/// printed "offset (19.99999944368998, 60.00000055631002) mm".
#[test]
fn centring_a_round_drawing_gives_a_round_offset() {
    let text = doc(r#"width="40mm" height="40mm" viewBox="0 0 40 40""#, SQUARE);
    let drawn = pcpp::pipeline::load_path(text.as_bytes(), "sq.svg").unwrap();
    let Some((lo, hi)) = pcpp::demo::test_part::test_part().bbox() else {
        panic!("the demo part has no triangles");
    };
    let footprint = (lo.truncate(), hi.truncate());
    assert_eq!(footprint, (v(0.0, 0.0), v(80.0, 80.0)));
    let (placement, note) =
        pcpp::placement::centre_drawing(&drawn.subpaths, footprint, &Placement::IDENTITY, true)
            .unwrap();
    assert_eq!(note, None);
    assert_eq!(placement.offset_mm, v(20.0, 60.0));
    // The line drawn 32 mm long is printed 32 mm long.
    let placed = placement.apply_subpath(&drawn.subpaths[0]);
    assert_eq!(placed.points[0], v(24.0, 56.0));
    assert_eq!(placed.points[1].distance(placed.points[0]), 32.0);
}

/// Transparent shapes (`opacity`, `stroke-opacity` with no fill, a
/// transparent group) were printed, and clipped or masked shapes printed
/// whole without a word (exploratory QA): a viewer shows nothing of the
/// first, and only a part of the second. Now the transparent are left out
/// with the shapes not drawn, and the clipped are named.
#[test]
fn regression_transparent_shapes_were_printed_and_clipped_ones_printed_whole_unsaid() {
    let (subs, notes) = notes_of(&doc(
        MM,
        r#"<path id="gone" d="M 0 0 L 10 0" stroke="black" opacity="0"/>
           <path d="M 0 1 L 10 1" stroke="black" stroke-opacity="0" fill="none"/>
           <g opacity="0"><path d="M 0 2 L 10 2" stroke="black"/></g>
           <path id="faint" d="M 0 3 L 10 3" stroke="black" stroke-opacity="0.2"/>
           <path id="kept" d="M 0 5 L 10 5" stroke="black" fill-opacity="0"/>"#,
    ));
    assert_eq!(subs.len(), 2, "{subs:?}");
    let note = note_with(&notes, "were not printed");
    assert!(
        note.starts_with("3 shape(s)") && note.contains("transparent") && note.contains("'gone'"),
        "{note}"
    );
    no_note_with(&notes, "clipped");
    let (subs, notes) = notes_of(&doc(
        MM,
        r#"<defs><clipPath id="c"><rect x="0" y="0" width="30" height="15"/></clipPath>
           <mask id="m"><rect x="0" y="0" width="30" height="15" fill="white"/></mask></defs>
           <circle id="half" cx="15" cy="15" r="10" stroke="black" fill="none" clip-path="url(#c)"/>
           <g mask="url(#m)"><path d="M 0 5 L 10 5" stroke="black"/></g>
           <path d="M 0 25 L 10 25" stroke="black"/>"#,
    ));
    assert_eq!(subs.len(), 3, "{subs:?}");
    let note = note_with(&notes, "clipped or masked");
    assert!(
        note.starts_with("2 shape(s)") && note.contains("(clip-path, mask; the first: 'half')"),
        "{note}"
    );
}

/// QA round 22 F2: matplotlib's `savefig` writes its figure's and axes'
/// backgrounds as white rectangles with no stroke, and clips every plotted
/// line to the axes: the rectangles were printed as squares of ink round
/// the drawing, and every line was said to be clipped. A white unstroked
/// shape before anything else printed, whose box holds all that is printed
/// after it, is a background, left out with a note; a clip that is a
/// rectangle holding the whole shape cuts nothing, and one that cuts a
/// shape is still named. A white shape drawn over others (a knock-out),
/// one that holds less (a pad drawn first) and a drawing of white shapes
/// alone (a logo for a dark page: review) are printed, as before.
#[test]
fn a_plots_white_backgrounds_are_not_printed_and_a_clip_that_cuts_nothing_is_not_said() {
    let (subs, notes) = notes_of(&doc(
        MM,
        r##"<defs><clipPath id="axes"><rect x="5" y="5" width="40" height="30"/></clipPath>
           <clipPath id="half"><rect x="5" y="5" width="20" height="30"/></clipPath></defs>
           <path id="patch_1" d="M 0 50 L 50 50 L 50 0 L 0 0 z" style="fill: #ffffff"/>
           <rect id="patch_2" x="5" y="5" width="40" height="30" fill="white"/>
           <path id="line2d_1" d="M 10 10 L 40 30" clip-path="url(#axes)" style="fill: none; stroke: #1f77b4"/>
           <path id="line2d_2" d="M 10 20 L 40 20" clip-path="url(#half)" style="fill: none; stroke: #ff7f0e"/>
           <circle id="knockout" cx="25" cy="15" r="3" fill="#fff"/>"##,
    ));
    assert_eq!(sources(&subs), ["line2d_1", "line2d_2", "knockout"]);
    let note = note_with(&notes, "background");
    assert!(
        note.starts_with("2 white shape(s) with no stroke") && note.contains("'patch_1'"),
        "{note}"
    );
    let note = note_with(&notes, "clipped or masked");
    assert!(
        note.starts_with("1 shape(s)") && note.contains("the first: 'line2d_2'"),
        "{note}"
    );
    let note = note_with(&notes, "filled but not stroked");
    assert!(
        note.starts_with("1 shape(s)") && note.contains("'knockout'"),
        "{note}"
    );
    // A white page under a line that runs past it (a plot's glyphs may):
    // the page covers the whole page, a background all the same.
    let (subs, notes) = notes_of(&doc(
        MM,
        r#"<rect id="page" x="0" y="0" width="100" height="100" fill="white"/>
           <path id="long" d="M 10 10 L 120 10" stroke="black"/>"#,
    ));
    assert_eq!(sources(&subs), ["long"]);
    assert!(note_with(&notes, "background").contains("'page'"));
    // A clip whose outline runs along two sides of its box, of no area:
    // it cuts (review).
    let (_, notes) = notes_of(&doc(
        MM,
        r#"<defs><clipPath id="z"><path d="M0 0 L100 0 L0 0 L0 100"/></clipPath></defs>
           <path id="gone" d="M 10 10 L 40 40" stroke="black" clip-path="url(#z)"/>"#,
    ));
    assert!(note_with(&notes, "clipped or masked").contains("'gone'"));
    // A white pad drawn first, beside a trace: printed.
    let (subs, notes) = notes_of(&doc(
        MM,
        r#"<rect id="pad" x="0" y="0" width="4" height="4" fill="white"/>
           <path id="trace" d="M 10 10 L 30 10" stroke="black"/>"#,
    ));
    assert_eq!(sources(&subs), ["pad", "trace"]);
    no_note_with(&notes, "background");
    assert!(note_with(&notes, "filled but not stroked").contains("'pad'"));
    // White shapes alone: printed.
    let (subs, notes) = notes_of(&doc(
        MM,
        r##"<path id="logo" d="M 5 5 L 20 5 L 20 20 z" fill="#fff"/>
           <circle id="dot" cx="30" cy="30" r="2" fill="white"/>"##,
    ));
    assert_eq!(subs.len(), 2, "{subs:?}");
    no_note_with(&notes, "background");
    let note = note_with(&notes, "filled but not stroked");
    assert!(
        note.starts_with("2 shape(s)") && note.contains("'logo'"),
        "{note}"
    );
}

/// QA round 23 F1: a symbol placed by `<use transform>` whose content runs
/// outside its viewport was printed whole without the clip note (the
/// viewer cuts it): usvg gives the clipped group it makes a frame without
/// the use's transform, so the viewport was taken 50 units off: it held
/// the shape on a 300 unit page, and on a 100 unit one a shape it holds
/// was said to be cut. The same symbol placed by `x` and `y`, and a clip
/// on a translated group of one's own, were already said.
#[test]
fn regression_a_symbol_placed_by_a_use_transform_is_said_to_be_clipped() {
    for (label, body) in [
        (
            "use transform",
            r##"<use href="#s" transform="translate(50,50)"/>"##,
        ),
        ("use x y", r##"<use href="#s" x="50" y="50"/>"##),
        (
            "group",
            r##"<g transform="translate(50,50)" clip-path="url(#c)"><rect id="r" x="-20" y="-10" width="120" height="120" fill="none" stroke="black"/></g>"##,
        ),
    ] {
        let (subs, notes) = notes_of(&doc(
            r#"width="300mm" height="300mm" viewBox="0 0 300 300""#,
            &format!(
                r##"<defs><clipPath id="c"><rect width="300" height="300"/></clipPath>
                   <symbol id="s"><rect id="r" x="-20" y="-10" width="120" height="120" fill="none" stroke="black"/></symbol></defs>
                   {body}"##
            ),
        ));
        assert_eq!(subs.len(), 1, "{label}: {subs:?}");
        let note = note_with(&notes, "clipped or masked");
        assert!(note.starts_with("1 shape(s)"), "{label}: {note}");
    }
    let (_, notes) = notes_of(&doc(
        MM,
        r##"<defs><symbol id="s"><rect x="20" y="10" width="60" height="60" fill="none" stroke="black"/></symbol></defs>
           <use href="#s" transform="translate(50,50)"/>"##,
    ));
    no_note_with(&notes, "clipped or masked");
}

/// QA round 23 F2: a `<use>` of an icon sprite sheet's symbol in another
/// file (as bootstrap-icons documents it), or of an id the drawing does
/// not have, drew nothing without a word; it is said, with the first's
/// line and href. A `<use>` that resolves is printed and not said.
#[test]
fn regression_a_use_of_nothing_in_the_drawing_is_said() {
    let (subs, notes) = notes_of(&doc(
        MM,
        r##"<defs><path id="line" d="M 10 10 L 40 10" stroke="black"/></defs>
<use href="../icons/sprite.svg#heart"/>
<use href="#gone"/>
<use href="#line" y="20"/>"##,
    ));
    assert_eq!(subs.len(), 1, "{subs:?}");
    let note = note_with(&notes, "<use>(s) refer to nothing");
    assert!(
        note.starts_with("2 <use>(s) refer to nothing in this drawing, so nothing is printed")
            && note.contains(
                "(the first, line 2: href=\"../icons/sprite.svg#heart\", in another file, which \
                 is not read)"
            ),
        "{note}"
    );
    let (_, notes) = notes_of(&doc(
        MM,
        r##"<use href="#gone"/><path d="M 0 0 L 9 9" stroke="black"/>"##,
    ));
    assert!(
        note_with(&notes, "<use>(s) refer")
            .contains("href=\"#gone\", an id this drawing does not have"),
        "{notes:?}"
    );
    // Resolved, or in a definition nothing uses (it draws nothing
    // anyway: review): not said; in one that is used: said.
    let (_, notes) = notes_of(&doc(
        MM,
        r##"<defs><path id="line" d="M 10 10 L 40 10" stroke="black"/><g id="unused"><use href="#gone"/></g></defs><use xlink:href="#line" xmlns:xlink="http://www.w3.org/1999/xlink"/>"##,
    ));
    no_note_with(&notes, "<use>");
    let (_, notes) = notes_of(&doc(
        MM,
        r##"<defs><g id="used"><path d="M 10 10 L 40 10" stroke="black"/><use href="data:image/svg+xml;base64,AAAA"/></g></defs><use href="#used"/>"##,
    ));
    assert!(
        note_with(&notes, "<use>(s) refer").contains("a data: URL, which is not read"),
        "{notes:?}"
    );
}

/// QA round 23 F3: the root's `background-color` (resvg's own test) was
/// printed as a rectangle round the page, named 'use instance'. A page's
/// colour is no shape: left out, with a note; the shapes are printed, and
/// a root without one is read as before.
#[test]
fn regression_the_pages_background_colour_is_not_printed() {
    let body =
        r#"<rect id="rect1" x="20" y="20" width="60" height="60" fill="none" stroke="green"/>"#;
    for root in [
        r#"style="background-color: #0000ff80;""#,
        r#"style="fill:none; background-color : red""#,
        r#"background-color="white""#,
    ] {
        let (subs, notes) = notes_of(&doc(&format!("{MM} {root}"), body));
        assert_eq!(sources(&subs), ["rect1"], "{root}");
        let note = note_with(&notes, "background-color");
        assert!(
            note.starts_with("the root <svg>'s background-color is not printed"),
            "{root}: {note}"
        );
    }
    // None (CSS names are lower case; `none` is no colour), and an
    // id-less filled rectangle first (a `<use>`'s) under a root group of
    // usvg's: printed, not said (review).
    for root in [
        "",
        r#"style="BACKGROUND-COLOR: red""#,
        r#"style="background-color: none""#,
    ] {
        let (subs, notes) = notes_of(&doc(
            &format!(r#"width="100mm" height="100mm" viewBox="0 0 50 50" {root}"#),
            &format!(
                r##"<defs><rect id="pad" width="5" height="5" fill="blue"/></defs><use href="#pad"/>{body}"##
            ),
        ));
        assert_eq!(subs.len(), 2, "{root}: {subs:?}");
        no_note_with(&notes, "background");
    }
}

/// A UTF-16 SVG (Windows tools write them) was "not UTF-8 text (invalid
/// utf-8 sequence of 1 bytes from index 0)", then refused with "save it as
/// UTF-8"; its byte-order mark says how to read it, and it is read.
#[test]
fn a_utf16_svg_is_read_by_its_byte_order_mark() {
    let text = doc(
        MM,
        "<title>\u{e9}t\u{e9} \u{1F4E1}</title><path d=\"M 0 0 L 10 0\" stroke=\"black\"/>",
    );
    let want = import_svg(text.as_bytes(), "u8.svg").unwrap();
    for bom in [[0xFF, 0xFE], [0xFE, 0xFF]] {
        let mut bytes = bom.to_vec();
        for u in text.encode_utf16() {
            let pair = if bom[0] == 0xFF {
                u.to_le_bytes()
            } else {
                u.to_be_bytes()
            };
            bytes.extend_from_slice(&pair);
        }
        assert_eq!(import_svg(&bytes, "u16.svg").unwrap(), want);
        // Without its byte-order mark too (the '<' and a zero byte tell).
        assert_eq!(import_svg(&bytes[2..], "u16.svg").unwrap(), want);
        // Cut short by one byte: refused, naming the file.
        let e = import_svg(&bytes[..bytes.len() - 1], "u16.svg")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("u16.svg") && e.contains("odd number of bytes"),
            "{e}"
        );
    }
}

/// QA round 7 F12: a PNG picked as the drawing was told to be saved as
/// UTF-8. Pictures and documents are named as what they are.
#[test]
fn a_picture_chosen_as_the_drawing_is_named_as_one() {
    for (bytes, kind) in [
        (&b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR"[..], "a PNG image"),
        (&b"\xff\xd8\xff\xe0\0\x10JFIF"[..], "a JPEG image"),
        (&b"%PDF-1.7\n%\xe2\xe3"[..], "a PDF document"),
        (&b"GIF89a\x01\0"[..], "a GIF image"),
        (&b"RIFF\x10\0\0\0WEBPVP8 "[..], "a WebP image"),
        (&b"BM\x36\x10\0\0\0\0"[..], "a BMP image"),
        (&b"II*\0\x08\0\0\0"[..], "a TIFF image"),
        (&b"MM\0*\0\0\0\x08"[..], "a TIFF image"),
    ] {
        let e = import_svg(bytes, "pic.svg").unwrap_err().to_string();
        assert!(
            e.contains(&format!("this is {kind}, not an SVG drawing"))
                && e.contains("pic.svg")
                && !e.contains("UTF-8"),
            "{e}"
        );
    }
}

/// An SVG saved by an older editor in ISO-8859-1 or windows-1252, as its
/// XML declaration says (a QA finding: "not UTF-8 text (invalid utf-8
/// sequence of 1 bytes from index 146)"), is read as declared; a byte
/// that is not UTF-8 with no such declaration, or another encoding, is
/// refused naming the line and what to do.
#[test]
fn a_latin1_or_cp1252_svg_is_read_as_its_declaration_says() {
    let body = |enc: &str, title: &[u8]| -> Vec<u8> {
        let mut b = format!(
            "<?xml version=\"1.0\" encoding=\"{enc}\"?>\n<svg \
             xmlns=\"http://www.w3.org/2000/svg\" width=\"50mm\" height=\"50mm\" \
             viewBox=\"0 0 50 50\">\n<title>"
        )
        .into_bytes();
        b.extend_from_slice(title);
        // The same characters name the path: its `source` shows how they
        // were decoded.
        b.extend_from_slice(b"</title><path id=\"");
        b.extend_from_slice(title);
        b.extend_from_slice(
            b"\" d=\"M 5 5 L 45 5 A 10 10 0 0 1 45 25\" stroke=\"black\" \
              fill=\"none\"/></svg>\n",
        );
        b
    };
    let want = import_svg(&body("UTF-8", "\u{e9}t\u{e9}\u{20ac}".as_bytes()), "u8.svg").unwrap();
    assert_eq!(want[0].source, "\u{e9}t\u{e9}\u{20ac}");
    // 0xE9 is e-acute in each, 0x80 the euro sign in cp1252 and the
    // control character U+0080 in ISO-8859-1 (and US-ASCII, read as it).
    for (enc, id) in [
        ("ISO-8859-1", "\u{e9}t\u{e9}\u{80}"),
        ("latin1", "\u{e9}t\u{e9}\u{80}"),
        ("windows-1252", "\u{e9}t\u{e9}\u{20ac}"),
        ("US-ASCII", "\u{e9}t\u{e9}\u{80}"),
    ] {
        let got = import_svg(&body(enc, b"\xe9t\xe9\x80"), "old.svg").unwrap();
        assert_eq!(got[0].points, want[0].points, "{enc}");
        assert_eq!(got[0].source, id, "{enc}");
    }
    // Declared UTF-16, written in one-byte characters: said so.
    let e = import_svg(&body("UTF-16", b"\xe9t\xe9"), "u.svg")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("names 'UTF-16', but the text is not UTF-16"),
        "{e}"
    );
    let e = import_svg(&body("KOI8-R", b"\xe9t\xe9"), "koi.svg")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("koi.svg")
            && e.contains("line 3")
            && e.contains("'KOI8-R'")
            && e.contains("save it as UTF-8"),
        "{e}"
    );
    let mut undeclared = body("UTF-8", b"\xe9t\xe9");
    undeclared.drain(..undeclared.iter().position(|&b| b == b'\n').unwrap() + 1);
    let e = import_svg(&undeclared, "plain.svg")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("plain.svg")
            && e.contains("line 2, byte 0xE9")
            && e.contains("encoding=\"ISO-8859-1\""),
        "{e}"
    );
}

/// A scan or a program chosen as the drawing read "not well-formed XML:
/// unknown token at 1:1" (a QA run gave an OBJ); it is named for what it
/// looks like.
#[test]
fn a_scan_or_program_chosen_as_the_drawing_is_named() {
    let cases: [(&[u8], &str); 6] = [
        (
            b"####\n# OBJ File Generated by Meshlab\n####\nv 1 2 3\nf 1 2 3\n",
            "it looks like a Wavefront OBJ scan",
        ),
        (
            b"solid part\n facet normal 0 0 1\n",
            "it looks like an STL scan",
        ),
        (
            b"; pcpp 0.1.0\nG21\nG90\n",
            "it looks like a G-code program",
        ),
        (b"ply\nformat ascii 1.0\n", "it looks like a PLY scan"),
        (
            b"ply\nformat binary_little_endian 1.0\nend_header\n\xff\xfe\x00",
            "it looks like a binary PLY scan",
        ),
        (b"12 34 56\n", "does not start with '<'"),
    ];
    for (bytes, expected) in cases {
        let e = pcpp::pipeline::load_path(bytes, "drawing.svg")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("drawing.svg: not ") && e.contains(expected),
            "{e}"
        );
    }
}

/// A root size CSS reads and svgtypes did not (white space around it, the
/// unit in capitals, the quarter-millimetre Q) was ignored: the page taken
/// as 100 px, a 50 mm line printed 26.46 mm long with nothing said.
#[test]
fn root_sizes_as_css_writes_them_give_the_size_in_mm() {
    for size in ["5.0cm ", " 50mm", "50MM", "5CM", "200Q", "200q", "50mm"] {
        let text = doc(
            &format!(r#"width="{size}" height="{size}" viewBox="0 0 100 100""#),
            r#"<path d="M0,50 H100" stroke="black"/>"#,
        );
        let (subs, notes) = notes_of(&text);
        assert!(
            (subs[0].length_mm() - 50.0).abs() < 1e-9,
            "{size:?}: {}",
            subs[0].length_mm()
        );
        assert!(notes.is_empty(), "{size:?}: {notes:?}");
    }
}

/// A root size that is no length, or one set in CSS, leaves the size in
/// mm unknown: refused, naming the attribute, not printed at a guess.
#[test]
fn root_sizes_that_are_no_length_are_refused_by_name() {
    for (size, named) in [
        (
            r#"width="50 mm" height="50mm""#,
            r#"width="50 mm" is not a length"#,
        ),
        (
            r#"width="50vw" height="50vw""#,
            r#"width="50vw" and height="50vw" are not lengths"#,
        ),
        (
            r#"style="width:50mm;height:50mm""#,
            "sets its width and height",
        ),
    ] {
        let text = doc(
            &format!(r#"{size} viewBox="0 0 100 100""#),
            r#"<path d="M0,50 H100" stroke="black"/>"#,
        );
        let e = import_svg(text.as_bytes(), "size.svg")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("size.svg: the root <svg>'s "), "{e}");
        assert!(
            e.contains(named) && e.contains("e.g. width=\"50mm\""),
            "{e}"
        );
    }
}

/// Inkscape before 0.92 drew at 90 px per inch: its files are read at 90
/// (a 40 mm line stays 40 mm), said in a note; Inkscape 1.x's are not, nor
/// a legacy file whose size is in mm through a viewBox. Illustrator's
/// points-as-px are read at 72 per inch, by the same rule: the size the
/// drawing had in its editor (QA F14: it was read at a browser's size).
#[test]
fn legacy_inkscape_px_are_read_at_90_per_inch_and_illustrator_at_72() {
    let ink = |version: &str, size: &str| {
        format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" inkscape:version="{version}" {size}><path d="m 70.866142,70.866142 141.732288,0" stroke="black"/></svg>"#
        )
    };
    let a4_px = r#"width="744.09448819" height="1052.3622047""#;
    let (subs, notes) = notes_of(&ink("0.48.4 r9939", a4_px));
    assert!(
        (subs[0].length_mm() - 40.0).abs() < 1e-5,
        "{}",
        subs[0].length_mm()
    );
    assert!(
        (subs[0].points[0].x - 20.0).abs() < 1e-5,
        "{}",
        subs[0].points[0]
    );
    let note = note_with(&notes, "Inkscape 0.48.4");
    assert!(note.contains("90 px per inch"), "{note}");
    // A note's size in mm is the size printed: a stroke 9 px wide is 2.54 mm
    // at 90 px per inch (2.38 mm read at 96 was said before).
    let wide = ink("0.48.4 r9939", a4_px)
        .replace(r#"stroke="black""#, r#"stroke="black" stroke-width="9""#);
    let (_, notes) = notes_of(&wide);
    let note = note_with(&notes, "the widest");
    assert!(note.contains("is drawn 2.54 mm wide"), "{note}");
    for (version, size) in [
        ("1.3 (0e150ed6c4, 2023-07-21)", a4_px),
        (
            "0.48.4 r9939",
            r#"width="210mm" height="297mm" viewBox="0 0 744.09448819 1052.3622047""#,
        ),
    ] {
        let (subs, notes) = notes_of(&ink(version, size));
        // 141.73 user units: 210 / 744.09 mm each through the viewBox, else
        // CSS px.
        let want = if size.contains("mm") { 40.0 } else { 37.5 };
        assert!(
            (subs[0].length_mm() - want).abs() < 1e-5,
            "{version}: {}",
            subs[0].length_mm()
        );
        assert!(
            notes.iter().all(|n| !n.contains("90 px")),
            "{version}: {notes:?}"
        );
    }
    let ai = r#"<?xml version="1.0" encoding="utf-8"?>
<!-- Generator: Adobe Illustrator 27.0.0, SVG Export Plug-In . SVG Version: 6.00 Build 0)  -->
<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 170.08 113.39"><path d="M0,10 H72" stroke="black"/></svg>"#;
    let (subs, notes) = notes_of(ai);
    // 72 points: an inch.
    assert!(
        (subs[0].length_mm() - 25.4).abs() < 1e-5,
        "{}",
        subs[0].length_mm()
    );
    let note = note_with(&notes, "Adobe Illustrator");
    assert!(
        note.contains("read at 72 px per inch") && note.contains("0.75 times as large"),
        "{note}"
    );
    // Its size, and its stroke, in the same px: 6 pt is 2.117 mm.
    let note = note_with(&notes, "no width or height");
    assert!(
        note.contains(
            "px at 72 per inch (Illustrator's points) (60.0 x 40.0 mm), as the editor that \
             wrote it drew it"
        ),
        "{note}"
    );
    let (_, notes) =
        notes_of(&ai.replace(r#"stroke="black""#, r#"stroke="black" stroke-width="6""#));
    let note = note_with(&notes, "the widest");
    assert!(note.contains("is drawn 2.12 mm wide"), "{note}");
    // A file of Illustrator's sized in mm is read by its size.
    let (subs, notes) = notes_of(&ai.replace("viewBox=", r#"width="60mm" height="40mm" viewBox="#));
    assert!(
        // (The viewBox meets the page: the smaller of its two scales.)
        (subs[0].length_mm() - 72.0 * f64::min(60.0 / 170.08, 40.0 / 113.39)).abs() < 1e-5,
        "{}",
        subs[0].length_mm()
    );
    no_note_with(&notes, "72 px");
}

/// The one off-page note among `notes`.
fn the_off_page_note(notes: &[String]) -> &String {
    let off: Vec<&String> = notes
        .iter()
        .filter(|n| n.contains("off the page"))
        .collect();
    assert_eq!(off.len(), 1, "{notes:?}");
    off[0]
}

/// Found by QA: scraps beside an Inkscape page (a line from x 30 to 70 on
/// a 40 mm page) were printed with nothing said. Shapes off the page are
/// named once each; a page's edge is on it; a document with no size has no
/// page to be off.
#[test]
fn shapes_off_the_page_are_named() {
    let text = doc(
        PAGE_40,
        r#"<path id="offpage" d="M 30 10 H 70" stroke="black"/>
           <path id="edge" d="M 0 0 H 40 V 20" stroke="black"/>
           <path id="left" d="M -5 5 H 5 M -5 8 H 5" stroke="black"/>"#,
    );
    let (subs, notes) = notes_of(&text);
    assert_eq!(subs.len(), 4);
    let off = the_off_page_note(&notes);
    assert!(
        off.starts_with("2 shape(s) lie partly or wholly off the page (40.0 x 20.0 mm)")
            && off.contains("(the first: 'offpage')"),
        "{off}"
    );
    let inside = doc(
        PAGE_40,
        r#"<path d="M 0 0 H 40 V 20 H 0 Z" stroke="black"/>"#,
    );
    assert!(notes_of(&inside).1.is_empty());
    let no_size = r#"<svg xmlns="http://www.w3.org/2000/svg"><path d="M 300 10 H 700" stroke="black"/></svg>"#;
    assert!(!notes_of(no_size)
        .1
        .iter()
        .any(|n| n.contains("off the page")));
}

/// QA round 11 L2: an Inkscape 0.39 file's A4 page (width="210mm"
/// height="297mm", user units drawn at 90 px per inch) was said to be
/// 224.0 x 316.8 mm, and a shape just past its edge was not named: the
/// 90 px rule is for the drawing's user units, not for a page in mm.
#[test]
fn an_old_inkscapes_page_in_mm_keeps_its_size() {
    let text = r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" inkscape:version="0.39" width="210mm" height="297mm">
        <path id="inside" d="M 10 10 H 700" stroke="black"/>
        <path id="past" d="M 700 20 H 770" stroke="black"/></svg>"#;
    let (subs, notes) = notes_of(text);
    // 770 px at 90 per inch is 217.3 mm: the drawing is read at 90.
    let right = subs
        .iter()
        .flat_map(|s| &s.points)
        .map(|p| p.x)
        .fold(0.0, f64::max);
    assert!((right - 770.0 * 25.4 / 90.0).abs() < 1e-6, "{right}");
    let off = the_off_page_note(&notes);
    assert!(
        off.starts_with("1 shape(s) lie partly or wholly off the page (210.0 x 297.0 mm)")
            && off.contains("(the first: 'past')"),
        "{off}"
    );
}

/// `<use>`s that refer to each other in a loop ('a' uses 'b', 'b' uses
/// 'a') made usvg give up with "SVG data parsing failed cause nodes limit
/// reached"; the error names the loop's ids and lines. A `<use>` of
/// `<use>`s that multiply past usvg's million elements says so and what to
/// do. A `<use>` inside the element it refers to is skipped, as a browser
/// does, and the rest is read.
#[test]
fn use_loops_and_use_bombs_are_named() {
    let e = import_error(&doc(
        MM,
        "\n<g id=\"a\"><path d=\"M 5 5 L 45 5\" stroke=\"black\"/><use href=\"#b\"/></g>\
         \n<g id=\"b\"><use xlink:href=\"#a\" transform=\"translate(0,5)\"/></g>\n",
    ));
    assert!(
        e.contains("qa.svg")
            && e.contains("'a' uses '#b' (line 2), 'b' uses '#a' (line 3)")
            && e.contains("remove or retarget"),
        "{e}"
    );
    let mut body = String::from("<defs><path id=\"l0\" d=\"M 5 5 L 6 5\" stroke=\"black\"/>");
    for i in 1..12 {
        body.push_str(&format!("<g id=\"l{i}\">"));
        for _ in 0..10 {
            body.push_str(&format!("<use href=\"#l{}\"/>", i - 1));
        }
        body.push_str("</g>");
    }
    body.push_str("</defs><use href=\"#l11\"/>");
    let e = import_error(&doc(MM, &body));
    assert!(
        e.contains("qa.svg")
            && e.contains("more than a million elements")
            && e.contains("Unlink Clone"),
        "{e}"
    );
    let subs = import(&doc(
        MM,
        r##"<path d="M 5 5 L 45 5" stroke="black"/><g id="g"><use href="#g"/></g>"##,
    ));
    assert_eq!(subs.len(), 1, "{subs:?}");
    // A loop through 50,000 <use>s (the search recursed once a link and
    // overflowed the stack; each link's line was found by rescanning the
    // text): found, and named by its first links.
    let n = 50_000;
    let mut body = String::from("<defs>");
    for i in 0..n {
        body.push_str(&format!("<use id=\"u{i}\" href=\"#u{}\"/>\n", (i + 1) % n));
    }
    body.push_str("</defs><use href=\"#u0\"/>");
    let e = import_error(&doc(MM, &body));
    assert!(
        e.contains("'u0' uses '#u1' (line 1)") && e.contains("(50000 links in all)"),
        "{}",
        &e[..e.len().min(600)]
    );
}

/// An `<image>` was meant to get a note, but usvg drops images it does not
/// decode before they could be counted, and Inkscape 0.92's flowed text
/// (`<flowRoot>`) vanished without one (a QA finding): each is named,
/// with what to do, and the outlines beside them are read.
#[test]
fn images_and_flowed_text_are_noted() {
    let (subs, notes) = notes_of(&doc(
        MM,
        r#"<path d="M 5 5 L 45 5" stroke="black"/>
           <flowRoot><flowRegion><rect x="5" y="10" width="30" height="10"/></flowRegion><flowPara>Hi</flowPara></flowRoot>
           <image x="0" y="20" width="10" height="10" xlink:href="data:image/png;base64,iVBORw0KGgo="/>
           <image x="0" y="40" width="10" height="10" href="photo.jpg"/>"#,
    ));
    assert_eq!(subs.len(), 1, "{subs:?}");
    assert!(note_with(&notes, "image(s)").starts_with("2 image(s) ignored (<image>)"));
    let flowed = note_with(&notes, "flowRoot");
    assert!(flowed.starts_with("1 flowed text(s) skipped") && flowed.contains("Object to Path"));
}
