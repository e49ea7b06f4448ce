//! The references are made from the code, and these tests fail when one
//! has drifted from it: the tables of `[render]`'s keys in
//! docs/scene-format.md and the Python stubs' keywords of `Scene.render`
//! and integrator names (airlight.pyi) from the option declarations and
//! the integrator kinds; each command's options in docs/cli.md from its
//! `--help`. `AIRLIGHT_BLESS=1 cargo test --test reference_docs --
//! --test-threads=1` writes them anew.

use airlight::SceneFile;
use airlight::integrator::{INTEGRATOR_KEY, INTEGRATOR_OPTIONS, IntegratorKind};
use airlight::options::{NumberRange, OptionSpec, ValueKind};
use airlight::scene::RENDER_SETTINGS;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A value kind as the docs' tables spell it.
fn kind_text(kind: ValueKind) -> String {
    match kind {
        ValueKind::Bool => "bool".into(),
        ValueKind::Count { min, max } => format!("integer {min}–{max}"),
        ValueKind::Number(NumberRange::Finite) => "number".into(),
        ValueKind::Number(NumberRange::Positive) => "number > 0".into(),
        ValueKind::Number(NumberRange::NonNegative) => "number ≥ 0".into(),
        ValueKind::Colour => "colour ≥ 0".into(),
        ValueKind::Name(names) => names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", "),
    }
}

fn row<T: Default>(spec: &OptionSpec<T>, takes: Option<String>) -> String {
    let unit = if spec.unit.is_empty() { String::new() } else { format!(" ({})", spec.unit) };
    let takes = takes.map(|t| format!(" {t} |")).unwrap_or_default();
    format!("| `{}` |{takes} {}{unit} | {} | {} |\n", spec.key, kind_text(spec.kind), spec.default_text(), spec.doc)
}

fn markdown_tables() -> String {
    let mut out = String::from("| key | value | default | meaning |\n|---|---|---|---|\n");
    for spec in RENDER_SETTINGS {
        out += &row(spec, None);
    }
    out +=
        "\nIntegrator options (each integrator reads its own; the others ignore them, but they are still checked):\n\n";
    out += "| key | read by | value | default | meaning |\n|---|---|---|---|---|\n";
    for o in INTEGRATOR_OPTIONS {
        let takes: Vec<&str> = o.takes.iter().map(|k| k.name()).collect();
        let takes = if takes.len() == IntegratorKind::ALL.len() { "all".to_string() } else { takes.join(", ") };
        out += &row(&o.spec, Some(takes));
    }
    out
}

/// A keyword of `Scene.render` in the stubs.
fn python_type(kind: ValueKind) -> String {
    match kind {
        ValueKind::Bool => "bool".into(),
        ValueKind::Count { .. } => "int".into(),
        ValueKind::Number(_) => "float".into(),
        ValueKind::Colour => "float | tuple[float, float, float]".into(),
        ValueKind::Name(names) => {
            format!("Literal[{}]", names.iter().map(|n| format!("\"{n}\"")).collect::<Vec<_>>().join(", "))
        }
    }
}

fn stub_keywords() -> String {
    let mut out = String::new();
    let kinds = RENDER_SETTINGS.iter().map(|s| (s.key, s.kind));
    let kinds = kinds.chain(INTEGRATOR_OPTIONS.iter().map(|o| (o.spec.key, o.spec.kind)));
    for (key, kind) in kinds.filter(|(k, _)| *k != INTEGRATOR_KEY) {
        out += &format!("        {key}: {} | None = None,\n", python_type(kind));
    }
    out
}

/// Checks (or, blessed, rewrites) the text between `begin` and `end` in
/// `file`, each time they occur.
fn check_region(file: &Path, begin: &str, end: &str, generated: &str) {
    let text = std::fs::read_to_string(file).unwrap();
    let mut rebuilt = String::new();
    let mut rest = text.as_str();
    let mut found = 0;
    while let Some(a) = rest.find(begin) {
        let after = a + begin.len();
        let b = after + rest[after..].find(end).expect("an end marker after each begin");
        let body = &rest[after..b];
        let line_end = body.find('\n').map_or(0, |i| i + 1);
        rebuilt += &rest[..after + line_end];
        rebuilt += generated;
        let indent = &body[body.rfind('\n').map_or(body.len(), |i| i + 1)..];
        rebuilt += indent;
        rest = &rest[b..];
        found += 1;
    }
    rebuilt += rest;
    assert!(found > 0, "{} has no {begin} marker", file.display());
    if std::env::var_os("AIRLIGHT_BLESS").is_some() {
        std::fs::write(file, &rebuilt).unwrap();
    } else if rebuilt != text {
        let line = text.lines().zip(rebuilt.lines()).position(|(a, b)| a != b).map_or(0, |i| i + 1);
        panic!(
            "{} disagrees with the option declarations from line {line}; \
             run `AIRLIGHT_BLESS=1 cargo test --test reference_docs -- --test-threads=1` to write it anew",
            file.display()
        );
    }
}

#[test]
fn the_scene_format_tables_are_the_declarations() {
    let file = repository().join("docs/scene-format.md");
    check_region(&file, "<!-- render-options: begin -->", "<!-- render-options: end -->", &markdown_tables());
}

#[test]
fn the_python_stubs_take_every_declared_option() {
    let file = repository().join("crates/airlight-py/airlight.pyi");
    check_region(&file, "# render-options: begin", "# render-options: end", &stub_keywords());
}

#[test]
fn the_python_stubs_name_every_integrator() {
    let file = repository().join("crates/airlight-py/airlight.pyi");
    let names: Vec<String> = IntegratorKind::NAMES.iter().map(|n| format!("\"{n}\"")).collect();
    let literal = format!("_Integrator = Literal[{}]\n", names.join(", "));
    check_region(&file, "# integrators: begin", "# integrators: end", &literal);
}

#[test]
fn every_key_of_the_render_table_is_declared_once() {
    let keys: Vec<&str> = SceneFile::render_keys().collect();
    for key in &keys {
        assert_eq!(keys.iter().filter(|k| *k == key).count(), 1, "{key} declared twice");
    }
    assert!(keys.len() >= 20, "{keys:?}");
}

/// Every command, as its words on the command line.
const COMMANDS: &[&[&str]] = &[
    &["render"],
    &["merge"],
    &["submit", "slurm"],
    &["info"],
    &["compare"],
    &["study"],
    &["gi"],
    &["attenuation"],
    &["view"],
];

#[test]
fn the_cli_reference_holds_each_commands_help() {
    let file = repository().join("docs/cli.md");
    for words in COMMANDS {
        let out = Command::new(env!("CARGO_BIN_EXE_airlight")).args(*words).arg("--help").output().unwrap();
        assert!(out.status.success(), "{words:?}");
        let help = String::from_utf8(out.stdout).unwrap();
        let name = words.join(" ");
        let block = format!("```text\n{}\n```\n", help.trim_end());
        check_region(&file, &format!("<!-- help: {name} begin -->"), &format!("<!-- help: {name} end -->"), &block);
    }
}
