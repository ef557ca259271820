//! The interactive survey page (`survey fit --out DIR` writes `survey.html`; the committed
//! copy is `reports/survey.html`). Expected points come from the TOML records read here
//! with the `toml` crate; expected exponents of the drawn lines are OLS slopes computed
//! here from those records.

use std::collections::BTreeMap;
use std::path::Path;

use crate::common;

const PAIRS: [(&str, &str); 4] = [
    ("leg_length", "body_length"),
    ("leg_length", "mass"),
    ("body_length", "mass"),
    ("leg_length", "speed_top"),
];
const CLASSES: [&str; 4] = ["lower-biped", "full-biped", "quadruped", "hexapod"];

fn field(var: &str) -> &'static str {
    match var {
        "leg_length" => "leg_length_m",
        "body_length" => "body_length_m",
        "mass" => "mass_kg",
        "speed_top" => "speed_top_mps",
        other => panic!("unknown variable {other}"),
    }
}

/// A robot as its record gives it.
#[derive(Debug)]
struct Rec {
    name: String,
    class: String,
    fit: bool,
    exclusion: String,
    values: BTreeMap<&'static str, f64>,
}

fn records(dir: &Path) -> BTreeMap<String, Rec> {
    let mut out = BTreeMap::new();
    for e in std::fs::read_dir(dir.join("robots")).expect("robots") {
        let p = e.expect("entry").path();
        if p.extension().and_then(|x| x.to_str()) != Some("toml") {
            continue;
        }
        let t: toml::Table = std::fs::read_to_string(&p)
            .expect("read")
            .parse()
            .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        let s = |k: &str| t.get(k).and_then(|v| v.as_str()).unwrap_or("").to_string();
        let mut values = BTreeMap::new();
        for f in ["leg_length_m", "body_length_m", "mass_kg", "speed_top_mps"] {
            let v = t
                .get("values")
                .and_then(|v| v.get(f))
                .and_then(|d| d.get("value"))
                .and_then(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)));
            if let Some(v) = v {
                values.insert(f, v);
            }
        }
        out.insert(
            s("id"),
            Rec {
                name: s("name"),
                class: s("class"),
                fit: t.get("fit").and_then(|v| v.as_bool()).expect("fit"),
                exclusion: s("exclusion"),
                values,
            },
        );
    }
    out
}

fn unescape(s: &str) -> String {
    s.replace("&quot;", "\"")
        .replace("&#39;", "'")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&")
}

/// Attributes of an element's start tag (values are double-quoted in the page).
fn attrs(tag: &str) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let mut rest = tag;
    while let Some(eq) = rest.find("=\"") {
        let name = rest[..eq]
            .rsplit(|c: char| c.is_whitespace())
            .next()
            .unwrap_or("")
            .to_string();
        let after = &rest[eq + 2..];
        let end = after.find('"').expect("closing quote");
        out.insert(name, unescape(&after[..end]));
        rest = &after[end + 1..];
    }
    out
}

/// Start tags of `element` with `class` among its classes.
fn elements(html: &str, element: &str, class: &str) -> Vec<BTreeMap<String, String>> {
    let open = format!("<{element} ");
    html.split(&open)
        .skip(1)
        .map(|t| attrs(&t[..t.find('>').expect("tag end")]))
        .filter(|a| {
            a.get("class")
                .is_some_and(|c| c.split_whitespace().any(|x| x == class))
        })
        .collect()
}

/// (x, y, panel html) for each panel of the page.
fn panels(html: &str) -> Vec<(String, String, String)> {
    html.split("<figure class=\"panel\"")
        .skip(1)
        .map(|p| {
            let svg = &elements(p, "svg", "plot")[0];
            (svg["data-x"].clone(), svg["data-y"].clone(), p.to_string())
        })
        .collect()
}

fn ols_slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let xs: Vec<f64> = points.iter().map(|p| p.0.log10()).collect();
    let ys: Vec<f64> = points.iter().map(|p| p.1.log10()).collect();
    let mx = xs.iter().sum::<f64>() / n;
    let my = ys.iter().sum::<f64>() / n;
    let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    sxy / sxx
}

/// Checks a page against the records of `dataset`: one point per robot per panel that it
/// has both values for, with the record's name, class, fit status, exclusion and values;
/// each class's line with the OLS exponent of its fitted robots, and its band.
fn check_page(html: &str, dataset: &Path) {
    let recs = records(dataset);
    assert!(recs.len() > 40, "{} records", recs.len());
    let ps = panels(html);
    assert_eq!(
        ps.iter()
            .map(|p| (p.0.as_str(), p.1.as_str()))
            .collect::<Vec<_>>(),
        PAIRS.to_vec(),
        "Table 2's three panels in order, then top speed"
    );
    let mut plotted = BTreeMap::<&str, usize>::new();
    for (x, y, p) in &ps {
        let (fx, fy) = (field(x), field(y));
        let pts = elements(p, "circle", "pt");
        let mut seen = BTreeMap::new();
        for a in &pts {
            let id = a["data-id"].as_str();
            *seen.entry(id.to_string()).or_insert(0) += 1;
            let r = recs
                .get(id)
                .unwrap_or_else(|| panic!("{y}~{x}: point `{id}` is no record"));
            assert_eq!(a["data-name"], r.name, "{id} name");
            assert_eq!(a["data-class"], r.class, "{id} class");
            assert_eq!(a["data-fit"], r.fit.to_string(), "{id} fit");
            assert_eq!(a["data-exclusion"], r.exclusion, "{id} exclusion");
            assert_eq!(
                a["class"].contains("excluded"),
                !r.fit,
                "{id}: excluded robots are greyed"
            );
            for f in ["leg_length_m", "body_length_m", "mass_kg"] {
                let attr = format!("data-{}", f.replace('_', "-"));
                let got = a[&attr].as_str();
                match r.values.get(f) {
                    Some(v) => assert_eq!(
                        got.parse::<f64>().ok(),
                        Some(*v),
                        "{id} {f}: `{got}` vs record {v}"
                    ),
                    None => assert_eq!(got, "", "{id} {f}: record has no value"),
                }
            }
            // The speeds the tooltip lists: the top speed as the record gives it.
            let speeds = a["data-speeds-mps"].as_str();
            match r.values.get("speed_top_mps") {
                Some(v) => assert!(
                    speeds.split(';').any(|kv| kv == format!("top={v}")),
                    "{id}: speeds `{speeds}` lack top={v}"
                ),
                None => assert!(!speeds.contains("top="), "{id}: no top speed in its record"),
            }
        }
        for (id, r) in &recs {
            let shown = r.values.get(fx).is_some_and(|v| *v > 0.0)
                && r.values.get(fy).is_some_and(|v| *v > 0.0);
            let n = seen.get(id.as_str()).copied().unwrap_or(0);
            assert_eq!(
                n,
                usize::from(shown),
                "{y}~{x}: robot `{id}` shown {n} times"
            );
            if shown {
                *plotted.entry(id.as_str()).or_insert(0) += 1;
            } else {
                assert!(
                    p.contains(&format!("<li data-id=\"{id}\">")),
                    "{y}~{x}: `{id}` listed as not in the panel"
                );
            }
        }
        // Lines: each class's fitted exponent, computed here; a band for each.
        let lines = elements(p, "line", "fit");
        let bands = elements(p, "path", "band");
        for class in CLASSES {
            let pts: Vec<(f64, f64)> = recs
                .values()
                .filter(|r| r.fit && r.class == class)
                .filter_map(|r| Some((*r.values.get(fx)?, *r.values.get(fy)?)))
                .collect();
            // A class is fitted (and drawn) with at least 3 robots.
            if pts.len() < 3 {
                assert!(
                    !lines.iter().any(|l| l["data-class"] == class),
                    "{y}~{x}: a {class} line from {} robots",
                    pts.len()
                );
                continue;
            }
            let line = lines
                .iter()
                .find(|l| l["data-class"] == class)
                .unwrap_or_else(|| panic!("{y}~{x}: no {class} line"));
            let b: f64 = line["data-b"].parse().expect("data-b");
            let want = ols_slope(&pts);
            assert!(
                (b - want).abs() < 1e-9,
                "{y}~{x} {class}: b {b} vs OLS {want}"
            );
            assert!(
                bands.iter().any(|b| b["data-class"] == class),
                "{y}~{x}: no {class} band"
            );
        }
    }
    assert!(
        plotted.len() > 40,
        "most robots are plotted somewhere: {}",
        plotted.len()
    );
}

/// Nothing is fetched when the page is viewed.
fn check_self_contained(html: &str) {
    assert!(html.starts_with("<!DOCTYPE html>"));
    for banned in ["src=", "href=", "<link", "@import", "url(http", "url(//"] {
        assert!(!html.contains(banned), "page references `{banned}`");
    }
    assert!(html.contains("<script>") && html.contains("<svg"));
}

#[test]
fn committed_page_has_one_point_per_robot_with_its_record_values() {
    let html = std::fs::read_to_string(common::repo().join("reports/survey.html"))
        .expect("reports/survey.html is committed (regenerate: survey fit --out reports/)");
    check_self_contained(&html);
    check_page(&html, &common::repo().join("dataset"));
}

#[test]
fn fit_out_writes_the_page_of_the_dataset_it_fitted() {
    // A changed copy: an added robot, with a name that needs escaping, is one more point.
    let data = common::dataset_copy();
    std::fs::write(
        data.path().join("robots/html-test-quad.toml"),
        r#"id = "html-test-quad"
name = "Quad <\"test\"> & co"
class = "quadruped"
fit = true

[[sources]]
key = "spec"
kind = "datasheet"
url = "https://example.org/html-test-quad.pdf"

[values]
leg_length_m = { value = 0.27, source = "spec" }
body_length_m = { value = 0.61, source = "spec" }
mass_kg = { value = 7.5, source = "spec" }
"#,
    )
    .expect("write record");
    let out_dir = tempfile::tempdir().expect("tempdir");
    let out = common::survey(&[
        "fit",
        "--dataset",
        data.path().to_str().expect("utf-8"),
        "--out",
        out_dir.path().to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let html = std::fs::read_to_string(out_dir.path().join("survey.html")).expect("survey.html");
    check_self_contained(&html);
    check_page(&html, data.path());
    let escaped = "data-name=\"Quad &lt;&quot;test&quot;&gt; &amp; co\"";
    assert_eq!(
        html.matches(escaped).count(),
        3,
        "one point per size panel (it has no top speed)"
    );
    let leftovers: Vec<_> = std::fs::read_dir(out_dir.path())
        .expect("out")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}
