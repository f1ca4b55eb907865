//! `talus render`'s pictures say what they show: each picture of grains has, under the
//! heap, a length scale and the key to its colours (the colour bar of the field, with
//! its name, unit and range) or line sizes, in the scene's units; each plot's axes
//! carry units. Checked on a hand-built column whose stresses are known exactly, in the
//! SVG text and in the decoded PNG's pixels.

use std::f64::consts::PI;
use std::path::PathBuf;
use talus::analyze::input::{Grain, Input, Touch};
use talus::analyze::{self, Analysis, Options};
use talus::render::{self, Field, diverging, ramp, text};
use tiny_skia::Pixmap;

const N: usize = 6;
const WIDTH: u32 = 400;
const INK: [u8; 3] = [30, 30, 30];

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("talus-pictures-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A column of N disks (diameter 1, mass 1, g = 1) standing on a floor, each contact
/// carrying exactly the weight above it: grain k (from the bottom) has (N − k) m g under
/// it and (N − k − 1) m g on top. Its stress Σ f ⊗ l / (π r²) is σ_zz = (2N − 2k − 1) m g
/// / (π r), σ_xx = 0, so its pressure (σ_zz + σ_xx)/2 is (2N − 2k − 1)/π with r = 1/2:
/// 1/π at the top, (2N − 1)/π at the bottom.
fn column(units: &str) -> Analysis {
    let grains = (0..N)
        .map(|k| Grain {
            id: k as u32,
            x: 0.0,
            z: 0.5 + k as f64,
            theta: 0.0,
            radius: 0.5,
            mass: 1.0,
            fixed: false,
            area: PI / 4.0,
            corners: Vec::new(),
            ..Default::default()
        })
        .collect();
    let touches = (0..N)
        .map(|k| Touch {
            a: k,
            b: k.checked_sub(1),
            force: [0.0, (N - k) as f64],
            normal_force: (N - k) as f64,
            point: [0.0, k as f64],
        })
        .collect();
    let (length, force) = if units == "si" {
        ("m", "N")
    } else {
        ("sigma", "m g")
    };
    let input = Input {
        source: PathBuf::from("column"),
        scene: "column".into(),
        units: units.into(),
        step: 0,
        time: 12.5,
        grains,
        touches,
        g: 1.0,
        mu: None,
        log: None,
        length_unit: length.into(),
        force_unit: force.into(),
        period_x: 0.0,
        walls: Vec::new(),
    };
    analyze::analyze(input, &Options::default()).unwrap()
}

/// Renders `a` coloured by `field`; returns the folder.
fn draw(a: &Analysis, field: Field, name: &str) -> PathBuf {
    let dir = tmp(name);
    render::render(a, &dir, field, WIDTH).unwrap();
    dir
}

/// Rows of the picture that show the heap: the outline with its margin of 4 % of the
/// larger side, at the scale that fits its width into the picture (as `View::of`).
fn heap_rows(a: &Analysis) -> u32 {
    let o = &a.summary.outline;
    let pad = 0.04 * o.width.max(o.height);
    let scale = WIDTH as f64 / (o.width + 2.0 * pad);
    ((o.height + 2.0 * pad) * scale).ceil() as u32
}

/// The lines of the SVG group `<g id="id">`, empty if there is none.
fn group<'a>(svg: &'a str, id: &str) -> Vec<&'a str> {
    let open = format!("<g id=\"{id}\">");
    svg.lines()
        .skip_while(|l| *l != open)
        .skip(1)
        .take_while(|l| *l != "</g>")
        .collect()
}

fn attr<'a>(line: &'a str, name: &str) -> &'a str {
    let key = format!(" {name}=\"");
    let start = line
        .find(&key)
        .unwrap_or_else(|| panic!("{name} in {line}"))
        + key.len();
    &line[start..start + line[start..].find('"').unwrap()]
}

fn num(line: &str, name: &str) -> f64 {
    attr(line, name).parse().unwrap()
}

/// A `<text>` of a legend: its role, anchor point (x, and y on its baseline), glyph
/// size in pixels to the em, anchor and words.
struct Text {
    class: String,
    x: f64,
    y: f64,
    size: f64,
    end: bool,
    words: String,
}

fn texts(lines: &[&str]) -> Vec<Text> {
    (lines.iter().filter(|l| l.starts_with("<text")))
        .map(|l| Text {
            class: attr(l, "class").into(),
            x: num(l, "x"),
            y: num(l, "y"),
            size: num(l, "font-size"),
            end: attr(l, "text-anchor") == "end",
            words: l[l.find('>').unwrap() + 1..l.rfind("</text>").unwrap()].into(),
        })
        .collect()
}

fn text<'a>(texts: &'a [Text], class: &str) -> &'a Text {
    (texts.iter().find(|t| t.class == class)).unwrap_or_else(|| panic!("a {class} text"))
}

fn rgb(png: &Pixmap, x: u32, y: u32) -> [u8; 3] {
    let p = png.pixel(x, y).unwrap();
    [p.red(), p.green(), p.blue()]
}

/// Asserts that the PNG spells `t` as the SVG places it: the words drawn alone on white
/// at the SVG's place (its font size giving the legend's scale, its y the baseline)
/// have every inked pixel equal to the picture's, and some ink near the text's colour
/// (antialiased small glyphs rarely cover a whole pixel).
fn assert_spelled(png: &Pixmap, t: &Text, colour: [u8; 3]) {
    let k = (t.size / text::font_size(1) as f64).round() as u32;
    assert!(
        (t.size - text::font_size(k) as f64).abs() < 0.06,
        "size {}",
        t.size
    );
    let w = text::width(&t.words, k) as i64;
    let left = if t.end { t.x as i64 - w } else { t.x as i64 };
    let top = t.y as i64 - text::baseline(k) as i64;
    let mut alone = Pixmap::new(png.width(), png.height()).unwrap();
    alone.fill(tiny_skia::Color::WHITE);
    text::draw(&mut alone, left, top, &t.words, k, colour);
    let (mut inked, mut solid) = (0, 0);
    for y in 0..png.height() {
        for x in 0..png.width() {
            let want = rgb(&alone, x, y);
            if want == [255; 3] {
                continue;
            }
            inked += 1;
            let near = (want.iter().zip(colour)).all(|(&a, b)| a.abs_diff(b) <= 60);
            solid += near as usize;
            assert_eq!(rgb(png, x, y), want, "\"{}\" at ({x}, {y})", t.words);
        }
    }
    assert!(
        inked > 10 && solid > 0,
        "\"{}\": {inked} pixels inked",
        t.words
    );
}

/// The rows of the PNG that run through the whole colour ramp, as (y, left, right):
/// ramp(0) at the left end, ramp(1) at the right, and every pixel between the ramp's
/// colour at its place.
fn ramp_rows(png: &Pixmap) -> Vec<(u32, u32, u32)> {
    map_rows(png, ramp)
}

/// The rows of the PNG that run through the colour map `map` as `ramp_rows` does.
fn map_rows(png: &Pixmap, map: fn(f64) -> [u8; 3]) -> Vec<(u32, u32, u32)> {
    let ramp = map;
    let (c0, c1) = (ramp(0.0), ramp(1.0));
    (0..png.height())
        .filter_map(|y| {
            let x0 = (0..png.width()).find(|&x| rgb(png, x, y) == c0)?;
            let x1 = (0..png.width()).rev().find(|&x| rgb(png, x, y) == c1)?;
            let n = x1.checked_sub(x0).filter(|&n| n >= 20)?;
            (x0..=x1)
                .all(|x| rgb(png, x, y) == ramp((x - x0) as f64 / n as f64))
                .then_some((y, x0, x1))
        })
        .collect()
}

#[test]
fn the_grains_picture_has_a_colour_bar_of_the_pressure_with_unit_and_range() {
    let a = column("reduced");
    let dir = draw(&a, Field::Pressure, "pressure");
    let svg = std::fs::read_to_string(dir.join("grains.svg")).unwrap();
    let bar = group(&svg, "colour-bar");
    let words = texts(&bar);
    // The field, its unit (a 2D stress: force per length), and the range of the colours,
    // here the whole range: the 2nd and 98th percentiles of six values are the ends.
    assert_eq!(text(&words, "label").words, "pressure [m g/σ]");
    let (lo, hi): (f64, f64) = (
        text(&words, "min").words.parse().unwrap(),
        text(&words, "max").words.parse().unwrap(),
    );
    assert!((lo * PI - 1.0).abs() < 2e-3, "min {lo}, 1/π");
    let top = (2 * N - 1) as f64;
    assert!((hi * PI / top - 1.0).abs() < 2e-3, "max {hi}, {top}/π");
    // The gradient runs through the ramp's colours, ramp(0) first.
    let stops: Vec<&str> = bar[0].split("stop-color=\"").skip(1).collect();
    assert_eq!(stops.len(), 9);
    for (k, s) in stops.iter().enumerate() {
        let c = ramp(k as f64 / 8.0);
        assert!(
            s.starts_with(&format!("rgb({},{},{})", c[0], c[1], c[2])),
            "{s}"
        );
    }

    // In the PNG: the bar's rows run through the ramp left to right, under the heap, at
    // the place the SVG gives it; the top grain (lowest pressure) is ramp(0).
    let png = Pixmap::load_png(dir.join("grains.png")).unwrap();
    let rows = ramp_rows(&png);
    assert!(
        !rows.is_empty(),
        "no row of the PNG runs through the colour ramp"
    );
    let rect = bar.iter().find(|l| l.starts_with("<rect")).unwrap();
    let (y0, x0, x1) = rows[0];
    assert_eq!(x0 as f64, num(rect, "x"));
    assert_eq!((x1 - x0 + 1) as f64, num(rect, "width"));
    assert_eq!(y0 as f64, num(rect, "y"));
    assert_eq!(rows.len() as f64, num(rect, "height"), "the bar's rows");
    assert!(rows.iter().all(|r| r.1 == x0 && r.2 == x1));
    assert!(x1 - x0 >= WIDTH / 4, "a bar {} pixels long", x1 - x0);
    assert!(y0 >= heap_rows(&a), "the bar lies under the heap");
    let top_grain = a.input.grains.last().unwrap();
    let o = &a.summary.outline;
    let pad = 0.04 * o.width.max(o.height);
    let scale = WIDTH as f64 / (o.width + 2.0 * pad);
    let centre = |g: &Grain| {
        (
            ((g.x - o.left + pad) * scale) as u32,
            ((o.top + pad - g.z) * scale) as u32,
        )
    };
    let (x, y) = centre(top_grain);
    assert_eq!(rgb(&png, x, y), ramp(0.0), "the top grain");
    let (x, y) = centre(&a.input.grains[0]);
    assert_eq!(rgb(&png, x, y), ramp(1.0), "the bottom grain");
    // The label and the numbers are written in the PNG as in the SVG.
    for t in &words {
        assert_spelled(&png, t, INK);
    }
}

#[test]
fn units_follow_the_scene_and_every_field_but_plain_has_a_bar() {
    let a = column("si");
    for (field, label, ends) in [
        (Field::Pressure, "pressure [N/m]", None),
        // One contact under the top grain, two under the others.
        (Field::Contacts, "contacts [-]", Some(("1", "2"))),
        // Angles of a long axis, in [0, π).
        (
            Field::Orientation,
            "long axis from horizontal [rad]",
            Some(("0", "3.14")),
        ),
    ] {
        let name = format!("si-{}", label.split(' ').next().unwrap());
        let dir = draw(&a, field, &name);
        let svg = std::fs::read_to_string(dir.join("grains.svg")).unwrap();
        let words = texts(&group(&svg, "colour-bar"));
        assert_eq!(text(&words, "label").words, label);
        if let Some((lo, hi)) = ends {
            assert_eq!(text(&words, "min").words, lo, "{label}");
            assert_eq!(text(&words, "max").words, hi, "{label}");
        }
        let scale = texts(&group(&svg, "length-scale"));
        assert!(text(&scale, "label").words.ends_with(" m"), "SI length");
        let png = Pixmap::load_png(dir.join("grains.png")).unwrap();
        assert!(!ramp_rows(&png).is_empty(), "{label}: a bar in the PNG");
    }
    // One colour says nothing: no bar, but still a length scale.
    let dir = draw(&a, Field::Plain, "si-plain");
    let svg = std::fs::read_to_string(dir.join("grains.svg")).unwrap();
    assert!(group(&svg, "colour-bar").is_empty() && !svg.contains("colour-bar"));
    assert!(!group(&svg, "length-scale").is_empty());
    let png = Pixmap::load_png(dir.join("grains.png")).unwrap();
    assert!(ramp_rows(&png).is_empty(), "no colour bar without colours");
}

#[test]
fn every_picture_has_a_length_scale_of_a_round_length_drawn_to_scale() {
    let a = column("reduced");
    let dir = draw(&a, Field::Pressure, "scale");
    for stem in ["grains", "forces", "stress_crosses", "repose"] {
        let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).unwrap();
        let part = group(&svg, "length-scale");
        let words = texts(&part);
        let label = &text(&words, "label").words;
        let value: f64 = (label.strip_suffix(" σ"))
            .unwrap_or_else(|| panic!("{stem}: \"{label}\" in σ"))
            .parse()
            .unwrap();
        let mantissa = value / 10f64.powf(value.log10().floor());
        assert!(
            [1.0, 2.0, 5.0].iter().any(|m| (mantissa - m).abs() < 1e-9),
            "{stem}: {value} is round"
        );
        // Pixels per length from a grain's drawn radius (the grains are r = 1/2).
        let circle = svg.lines().find(|l| l.starts_with("<circle")).unwrap();
        let per_length = num(circle, "r") / 0.5;
        let bar = part[0];
        let length = num(bar, "width");
        assert!(
            (length - value * per_length).abs() <= 1.0,
            "{stem}: {length} pixels for {value} at {per_length} per sigma"
        );
        assert!(
            (0.08..=0.2).contains(&(length / WIDTH as f64)),
            "{stem}: about a fifth of the width"
        );
        // In the PNG: the bar is ink along its length, under the heap.
        let png = Pixmap::load_png(dir.join(format!("{stem}.png"))).unwrap();
        let y = (num(bar, "y") + 0.5 * num(bar, "height")) as u32;
        assert!(y >= heap_rows(&a), "{stem}: the scale lies under the heap");
        let x0 = num(bar, "x") as u32;
        for x in x0..x0 + length as u32 {
            assert_eq!(rgb(&png, x, y), INK, "{stem}: scale bar at x = {x}");
        }
        assert_spelled(&png, text(&words, "label"), INK);
        // Above it, the snapshot's time and its number of grains.
        let caption = texts(&group(&svg, "caption"));
        let caption = text(&caption, "caption");
        assert_eq!(
            caption.words,
            format!("t = 12.5 √(σ/g) · {N} grains"),
            "{stem}"
        );
        assert_spelled(&png, caption, INK);
    }
}

#[test]
fn the_force_network_and_stress_crosses_have_keys_in_units() {
    let a = column("reduced");
    let dir = draw(&a, Field::Pressure, "keys");
    // Forces: a wedge whose width at its end is the width a line has for the force
    // written there, the floor's N m g having the widest line.
    let svg = std::fs::read_to_string(dir.join("forces.svg")).unwrap();
    let key = group(&svg, "width-key");
    let words = texts(&key);
    assert_eq!(text(&words, "label").words, "normal force [m g]");
    let f: f64 = text(&words, "max").words.parse().unwrap();
    assert!(f > 0.0 && f <= N as f64, "key force {f}");
    let wmax = (svg.lines().filter(|l| l.starts_with("<line")))
        .map(|l| num(l, "stroke-width"))
        .fold(0.0, f64::max);
    let points: Vec<f64> = attr(key[0], "points")
        .split([' ', ','])
        .map(|v| v.parse().unwrap())
        .collect();
    let thick = points[5] - points[3];
    assert!(
        (thick / wmax - f / N as f64).abs() < 0.01,
        "wedge {thick} px for {f}, line {wmax} px for {N}"
    );
    let png = Pixmap::load_png(dir.join("forces.png")).unwrap();
    for t in &words {
        assert_spelled(&png, t, INK);
    }
    // Stress crosses: an arm per colour with the stress it stands for and its meaning.
    let svg = std::fs::read_to_string(dir.join("stress_crosses.svg")).unwrap();
    let key = group(&svg, "arm-key");
    let words = texts(&key);
    assert_eq!(text(&words, "label").words, "principal stress [m g/σ]");
    let values: Vec<&str> = (words.iter().filter(|t| t.class == "value"))
        .map(|t| t.words.as_str())
        .collect();
    assert_eq!(values.len(), 2);
    assert!(values[0].ends_with(" compression") && values[1].ends_with(" tension"));
    let png = Pixmap::load_png(dir.join("stress_crosses.png")).unwrap();
    for (t, colour) in words.iter().zip([INK, [30, 60, 200], [200, 40, 40]]) {
        assert_spelled(&png, t, colour);
    }
}

/// The angle of repose read four ways (issue 39): one key entry per reading in its
/// line's colour with both flanks' angles as `talus analyze` measured them, and each
/// reading's lines drawn in that colour.
#[test]
fn the_repose_picture_keys_each_reading_with_its_angles() {
    let a = column("reduced");
    let dir = draw(&a, Field::Pressure, "repose");
    let svg = std::fs::read_to_string(dir.join("repose.svg")).unwrap();
    let key = group(&svg, "line-key");
    let words = texts(&key);
    assert_eq!(
        text(&words, "label").words,
        "angle of repose [deg], left/right"
    );
    let values: Vec<&Text> = words.iter().filter(|t| t.class == "value").collect();
    let s = &a.summary;
    let r = &s.repose_readings;
    let deg = |v: f64| {
        if v.is_finite() {
            format!("{v:.1}")
        } else {
            "-".into()
        }
    };
    let want = [
        ("band", [&s.repose_left, &s.repose_right], INK),
        ("middle", [&r.middle[0], &r.middle[1]], [30, 90, 210]),
        ("apex-toe", [&r.apex_toe[0], &r.apex_toe[1]], [230, 130, 0]),
        ("steepest", [&r.steepest[0], &r.steepest[1]], [200, 30, 120]),
    ];
    assert_eq!(values.len(), want.len());
    let png = Pixmap::load_png(dir.join("repose.png")).unwrap();
    for (t, (name, flanks, colour)) in values.iter().zip(want) {
        let text = format!(
            "{name} {}/{}",
            deg(flanks[0].angle_deg),
            deg(flanks[1].angle_deg)
        );
        assert_eq!(t.words, text);
        assert_spelled(&png, t, colour);
        let stroke = format!("stroke=\"rgb({},{},{})\"", colour[0], colour[1], colour[2]);
        let drawn = svg
            .lines()
            .filter(|l| l.starts_with("<line") && l.contains(&stroke));
        let lines = flanks
            .iter()
            .filter(|f| f.line.iter().flatten().all(|v| v.is_finite()));
        assert_eq!(
            drawn.count(),
            lines.count(),
            "{name}: a line per flank read"
        );
    }
}

/// The paper's angle (`talus reproduce`, issue 40 item 5) is drawn beside talus's: a
/// fifth key entry "source: value ± spread" spelled in its colour, and dashed lines
/// from the apex down to the base at that angle on both flanks.
#[test]
fn the_papers_angle_is_drawn_from_the_apex_and_keyed_with_its_source() {
    let a = column("reduced");
    let dir = tmp("repose-paper");
    let marks = render::PaperMarks {
        repose_deg: Some(render::PaperNumber {
            value: 35.0,
            spread: Some(5.0),
            source: "paper 001 (Fig. 1)".into(),
        }),
    };
    render::render_marked(&a, &dir, Field::Pressure, WIDTH, &marks).unwrap();
    let svg = std::fs::read_to_string(dir.join("repose.svg")).unwrap();
    let words = texts(&group(&svg, "line-key"));
    let values: Vec<&Text> = words.iter().filter(|t| t.class == "value").collect();
    assert_eq!(values.len(), 5, "four readings and the paper's");
    assert_eq!(values[4].words, "paper 001 (Fig. 1): 35 ± 5");
    let green = [0, 140, 70];
    let png = Pixmap::load_png(dir.join("repose.png")).unwrap();
    assert_spelled(&png, values[4], green);
    // The dashes, in picture coordinates: each runs at 35° to the horizontal, and
    // together they reach from the apex to the base on both sides of it.
    let stroke = "stroke=\"rgb(0,140,70)\"";
    let dashes: Vec<[f64; 4]> = (svg.lines())
        .filter(|l| l.starts_with("<line") && l.contains(stroke))
        .map(|l| ["x1", "y1", "x2", "y2"].map(|k| num(l, k)))
        .collect();
    assert!(dashes.len() >= 4, "dashed: {} pieces", dashes.len());
    for d in &dashes {
        let angle = ((d[3] - d[1]).abs() / (d[2] - d[0]).abs())
            .atan()
            .to_degrees();
        assert!((angle - 35.0).abs() < 0.5, "a dash at {angle}°");
    }
    // Both flanks from one apex: as wide as 2 / tan 35° times as high (to a dash).
    let xs = dashes.iter().flat_map(|d| [d[0], d[2]]);
    let ys = dashes.iter().flat_map(|d| [d[1], d[3]]);
    let span = |v: Vec<f64>| {
        v.iter().fold(f64::NEG_INFINITY, |m, &x| m.max(x))
            - v.iter().fold(f64::INFINITY, |m, &x| m.min(x))
    };
    let (wide, high) = (span(xs.collect()), span(ys.collect()));
    let want = 2.0 / 35f64.to_radians().tan();
    assert!(
        (wide / high / want - 1.0).abs() < 0.15,
        "{wide} wide, {high} high"
    );
    // Without marks no such line is drawn (the test above counts four entries).
    let plain =
        std::fs::read_to_string(draw(&a, Field::Pressure, "repose-plain").join("repose.svg"))
            .unwrap();
    assert!(!plain.contains(stroke));
}

/// A pressure of both signs (the top grain pulled up by cohesion) is drawn on the
/// diverging map, symmetric about zero: red for tension, white for none, blue for
/// compression, its zero marked under the bar.
#[test]
fn a_pressure_of_both_signs_is_drawn_on_a_map_centred_on_zero() {
    let mut a = column("reduced");
    // The top contact pulls: the top grain's pressure turns negative.
    a.input.touches[N - 1].force[1] = -3.0;
    a.input.touches[N - 1].normal_force = -3.0;
    let a = analyze::analyze(a.input, &Options::default()).unwrap();
    let dir = draw(&a, Field::Pressure, "signed");
    let svg = std::fs::read_to_string(dir.join("grains.svg")).unwrap();
    let bar = group(&svg, "colour-bar");
    let words = texts(&bar);
    let (lo, hi): (f64, f64) = (
        text(&words, "min").words.parse().unwrap(),
        text(&words, "max").words.parse().unwrap(),
    );
    assert!(
        lo < 0.0 && (lo + hi).abs() < 1e-9,
        "symmetric: {lo} .. {hi}"
    );
    assert_eq!(text(&words, "zero").words, "0");
    let stops: Vec<&str> = bar[0].split("stop-color=\"").skip(1).collect();
    for (k, s) in stops.iter().enumerate() {
        let c = diverging(k as f64 / 8.0);
        assert!(s.starts_with(&format!("rgb({},{},{})", c[0], c[1], c[2])));
    }
    let mid = diverging(0.5);
    assert!(mid.iter().all(|&v| v > 240), "zero is near white: {mid:?}");
    // Grains in order, bottom first: the bottom one compressed (blue), the top one in
    // tension (red).
    let fills: Vec<[u8; 3]> = (svg.lines().filter(|l| l.starts_with("<circle")))
        .map(|l| {
            let v: Vec<u8> = (attr(l, "fill")
                .trim_start_matches("rgb(")
                .trim_end_matches(')'))
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    let (bottom, top) = (fills[0], fills[N - 1]);
    assert!(bottom[2] > bottom[0] + 50, "bottom blue: {bottom:?}");
    assert!(top[0] > top[2] + 50, "top red: {top:?}");
    let png = Pixmap::load_png(dir.join("grains.png")).unwrap();
    assert!(
        !map_rows(&png, diverging).is_empty(),
        "the diverging bar in the PNG"
    );
    assert!(ramp_rows(&png).is_empty(), "no sequential bar");
    assert_spelled(&png, text(&words, "zero"), INK);
}

/// P(f/⟨f⟩) is plotted on a logarithmic axis: its y ticks are powers of ten.
#[test]
fn the_force_distribution_is_plotted_on_a_log_axis() {
    let a = column("reduced");
    let dir = draw(&a, Field::Pressure, "pdf");
    let svg = std::fs::read_to_string(dir.join("force_distribution.svg")).unwrap();
    let ticks: Vec<i32> = (svg.split("</text>"))
        .filter_map(|s| s.rsplit('>').next().map(str::trim))
        .filter_map(|t| t.strip_prefix("1e").and_then(|e| e.parse().ok()))
        .collect();
    assert!(ticks.len() >= 2, "decade ticks: {ticks:?}");
    assert!(svg.contains("P(f / ⟨f⟩) [-]"), "the axis");
}

#[test]
fn every_plot_labels_both_axes_with_units() {
    let a = column("reduced");
    let dir = draw(&a, Field::Pressure, "plots");
    let plots: Vec<PathBuf> = (std::fs::read_dir(&dir).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "svg"))
        .filter(|p| {
            !["grains", "forces", "stress_crosses", "repose"]
                .iter()
                .any(|s| p.ends_with(format!("{s}.svg")))
        })
        .collect();
    assert!(plots.len() >= 3, "{plots:?}");
    for p in plots {
        let svg = std::fs::read_to_string(&p).unwrap();
        // plotters writes each label as the text of one element; an axis label is the
        // only text that ends in a bracketed unit.
        let units = (svg.split("</text>"))
            .filter_map(|s| s.rsplit('>').next().map(str::trim))
            .filter(|t| t.ends_with(']') && t.contains(" ["))
            .count();
        assert_eq!(units, 2, "{}: two axes with units", p.display());
    }
    let svg = std::fs::read_to_string(dir.join("base_profile.svg")).unwrap();
    assert!(svg.contains("X = x / l [-]") && svg.contains("S = 2σ / (ρ g h) [-]"));
}
