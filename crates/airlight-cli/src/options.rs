//! The film settings and integrator options as command-line flags, made
//! from the library's declarations ([`RENDER_SETTINGS`],
//! [`INTEGRATOR_OPTIONS`]): `--KEY VALUE` with the key's `_` as `-`, and
//! `--KEY[=false]` / `--no-KEY` for a yes-or-no option. A flag's help is the
//! option's doc line; its value is checked by the option's own check as
//! clap reads it.

use airlight::integrator::{INTEGRATOR_KEY, INTEGRATOR_OPTIONS, IntegratorDesc, IntegratorKind, IntegratorOption};
use airlight::options::{OptionError, OptionSpec, OptionValue, ValueKind, flag};
use airlight::scene::{RENDER_SETTINGS, RenderSettings};
use clap::builder::PossibleValuesParser;
use clap::{Arg, ArgAction, ArgMatches, Command};

/// Which integrator options a command takes as flags (every film setting
/// is a flag of each).
pub trait FlagSet: Clone + Send + Sync + 'static {
    fn takes(option: &IntegratorOption) -> bool;
}

/// Every integrator option (`render`).
#[derive(Clone, Debug, Default)]
pub struct EveryOption;

impl FlagSet for EveryOption {
    fn takes(_: &IntegratorOption) -> bool {
        true
    }
}

/// The options that a radiosity render reads (`gi`, which renders with
/// radiosity alone, so not `integrator` either): a flag it would not hear is
/// no flag of it.
#[derive(Clone, Debug, Default)]
pub struct RadiosityFlags;

impl FlagSet for RadiosityFlags {
    fn takes(option: &IntegratorOption) -> bool {
        option.spec.key != INTEGRATOR_KEY && option.takes.contains(&IntegratorKind::Radiosity)
    }
}

/// The options given on the command line, in the declarations' order.
#[derive(Clone, Debug, Default)]
pub struct OptionFlags<S: FlagSet = EveryOption> {
    pub given: Vec<(&'static str, OptionValue)>,
    set: std::marker::PhantomData<S>,
}

impl<S: FlagSet> OptionFlags<S> {
    /// Applies the film settings given to `settings` and the integrator
    /// options given to `integrator`. The values were checked as they were
    /// parsed; names and cross-checks may still fail, with the flag named.
    pub fn apply(&self, settings: &mut RenderSettings, integrator: &mut IntegratorDesc) -> Result<(), String> {
        let named = |e: OptionError| flag_message(&e);
        for (key, value) in &self.given {
            let result = settings.set(key, value).or_else(|| integrator.set(key, value));
            result.unwrap_or(Ok(())).map_err(named)?;
        }
        settings.validate()?;
        integrator.validate().map_err(named)
    }
}

/// An option's message with its flag for its key: "--light-steps must be …".
pub fn flag_message(e: &OptionError) -> String {
    match e.message.strip_prefix(e.key) {
        Some(rest) => format!("{}{rest}", flag(e.key)),
        None => e.message.clone(),
    }
}

/// What one flag needs of a declaration, whatever type it sets.
struct FlagSpec {
    key: &'static str,
    kind: ValueKind,
    help: String,
}

fn flag_spec<T: Default>(o: &OptionSpec<T>, takes: Option<String>) -> FlagSpec {
    let mut help = o.doc.trim_end_matches('.').to_string();
    if let Some(takes) = takes {
        let mut doc = help.chars();
        let first = doc.next().map(|c| c.to_lowercase().to_string()).unwrap_or_default();
        help = format!("{takes}: {first}{}", doc.as_str());
    }
    if !o.unit.is_empty() {
        help = format!("{help}, in {}", o.unit);
    }
    help = format!("{help} [default: {}]", o.default_text());
    FlagSpec { key: o.key, kind: o.kind, help }
}

fn flag_specs<S: FlagSet>() -> Vec<(FlagSpec, &'static str)> {
    let film = RENDER_SETTINGS.iter().map(|o| (flag_spec(o, None), "Film and sampling"));
    let integrators = INTEGRATOR_OPTIONS.iter().filter(|o| S::takes(o)).map(|o| {
        let takes = (o.spec.key != INTEGRATOR_KEY).then(|| {
            let names: Vec<&str> = o.takes.iter().map(|k| k.name()).collect();
            names.join(", ")
        });
        (flag_spec(&o.spec, takes), "Integrator options")
    });
    film.chain(integrators).collect()
}

fn no_flag(key: &'static str) -> String {
    format!("no-{}", key.replace('_', "-"))
}

impl<S: FlagSet> clap::Args for OptionFlags<S> {
    fn augment_args(mut cmd: Command) -> Command {
        for (spec, heading) in flag_specs::<S>() {
            let (key, kind) = (spec.key, spec.kind);
            let long = key.replace('_', "-");
            let check = move |s: &str| kind.check(key, &OptionValue::parse_word(s)).map(|_| OptionValue::parse_word(s));
            let arg = Arg::new(key).long(long.clone()).help(spec.help).help_heading(heading);
            let arg = match kind {
                ValueKind::Bool => arg
                    .num_args(0..=1)
                    .require_equals(true)
                    .default_missing_value("true")
                    .value_name("true|false")
                    .value_parser(move |s: &str| check(s).map_err(|e| flag_message(&e))),
                ValueKind::Name(names) => arg.value_name("NAME").value_parser(PossibleValuesParser::new(names)),
                ValueKind::Count { .. } => {
                    arg.value_name("N").value_parser(move |s: &str| check(s).map_err(|e| flag_message(&e)))
                }
                ValueKind::Number(_) => {
                    arg.value_name("X").value_parser(move |s: &str| check(s).map_err(|e| flag_message(&e)))
                }
                ValueKind::Colour => {
                    arg.value_name("X|[R,G,B]").value_parser(move |s: &str| check(s).map_err(|e| flag_message(&e)))
                }
            };
            cmd = cmd.arg(arg);
            if kind == ValueKind::Bool {
                let no = no_flag(key);
                cmd = cmd.arg(
                    Arg::new(no.clone())
                        .long(no)
                        .action(ArgAction::SetTrue)
                        .help(format!("As --{long}=false"))
                        .help_heading(heading)
                        .conflicts_with(key),
                );
            }
        }
        cmd
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

impl<S: FlagSet> clap::FromArgMatches for OptionFlags<S> {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        let mut flags = OptionFlags { given: Vec::new(), set: std::marker::PhantomData };
        flags.update_from_arg_matches(matches)?;
        Ok(flags)
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        for (spec, _) in flag_specs::<S>() {
            let key = spec.key;
            let value = match spec.kind {
                ValueKind::Name(_) => matches.get_one::<String>(key).map(|s| OptionValue::Text(s.clone())),
                _ => matches.get_one::<OptionValue>(key).cloned(),
            };
            let value = value.or_else(|| {
                (spec.kind == ValueKind::Bool && matches.get_flag(&no_flag(key))).then_some(OptionValue::Bool(false))
            });
            if let Some(value) = value {
                self.given.retain(|(k, _)| *k != key);
                self.given.push((key, value));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        options: OptionFlags,
    }

    fn parse(args: &[&str]) -> Result<OptionFlags, String> {
        let argv = std::iter::once("airlight").chain(args.iter().copied());
        Cli::try_parse_from(argv).map(|c| c.options).map_err(|e| e.to_string())
    }

    #[test]
    fn every_declared_option_is_a_flag_that_sets_it() {
        let flags = parse(&[
            "--spp=3",
            "--steps",
            "7",
            "--no-stratify",
            "--reuse",
            "--integrator",
            "path",
            "--background",
            "[0.1,0.2,0.3]",
            "--patch-size",
            "0.5",
        ])
        .unwrap();
        let (mut s, mut d) = (RenderSettings::default(), IntegratorDesc::default());
        flags.apply(&mut s, &mut d).unwrap();
        assert_eq!(s.spp, 3);
        assert_eq!(d.raymarch.steps, 7);
        assert!(!d.stochastic.stratify && !d.path.stratify);
        assert!(d.path.reuse);
        assert_eq!(d.kind, airlight::integrator::IntegratorKind::Path);
        assert_eq!(s.background, glam::Vec3::new(0.1, 0.2, 0.3));
        assert_eq!(d.radiosity.patch_size, Some(0.5));
        let cmd = <Cli as clap::CommandFactory>::command();
        for key in airlight::SceneFile::render_keys() {
            assert!(cmd.get_arguments().any(|a| a.get_id() == key), "no flag for {key}");
        }
    }

    #[test]
    fn a_value_out_of_bounds_is_refused_with_its_flag() {
        let e = parse(&["--light-steps", "0"]).unwrap_err();
        assert!(e.contains("--light-steps must be an integer from 1 to 4096, got 0"), "{e}");
        let e = parse(&["--tonemap", "sepia"]).unwrap_err();
        assert!(e.contains("sepia") && e.contains("filmic"), "{e}");
        let e = parse(&["--reuse=maybe"]).unwrap_err();
        assert!(e.contains("--reuse must be true or false"), "{e}");
        assert!(parse(&["--reuse", "--no-reuse"]).is_err());
    }

    #[test]
    fn a_radiosity_command_has_no_flag_radiosity_does_not_read() {
        #[derive(Parser)]
        struct Gi {
            #[command(flatten)]
            options: OptionFlags<RadiosityFlags>,
        }
        let parse = |args: &[&str]| Gi::try_parse_from(std::iter::once("gi").chain(args.iter().copied()));
        for flag in ["--sampling=mis", "--integrator=path", "--max-depth=3", "--light-steps=4"] {
            assert!(parse(&[flag]).is_err(), "{flag}");
        }
        let gi = parse(&["--bounces=3", "--steps=8", "--spp=2"]).unwrap();
        let keys: Vec<&str> = gi.options.given.iter().map(|(k, _)| *k).collect();
        assert_eq!(keys, ["spp", "steps", "bounces"]);
    }
}
