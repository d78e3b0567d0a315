//! The viewer's keys: one table of bindings (keys, help, action), from which both the
//! dispatch of a key press and the help text (`H`, printed at start) come.

use clap::ValueEnum;
use winit::event::{ElementState, KeyEvent};
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::Key::{self, Character as Ch, Named};
use winit::keyboard::NamedKey;

use super::app::App;
use super::design::value_name;
use super::orbit;
use super::renderer::{BvhVariant, GridResolution, GridVariant, ShadowMode, TracerArg};
use super::window::Viewport;

/// Largest reflection depth the keys go to.
const MAX_REFL_DEPTH: u32 = 16;
/// Grid resolution step of the G keys.
const GRID_STEP: u32 = 4;
/// Light samples per axis the L keys go between (Klee 2016: 2×2 … 10×10).
const MIN_LIGHT_SAMPLES: u32 = 2;
const MAX_LIGHT_SAMPLES: u32 = 10;

/// The mouse's part of the help (the window's events handle the mouse).
const MOUSE: &str =
    "mouse: left drag orbit | right/middle drag or shift+left drag pan | wheel zoom";

/// A key press, as the actions see it.
struct Press<'a> {
    key: Key<&'a str>,
    shift: bool,
    event_loop: &'a ActiveEventLoop,
}

/// One row of the key table.
struct Binding {
    /// The keys as the help names them.
    label: &'static str,
    /// The logical keys that trigger it (characters as typed, letters in either case).
    keys: &'static [Key<&'static str>],
    /// What it does, as the help says it.
    does: &'static str,
    action: fn(&mut App, &Press),
}

const fn bind(
    label: &'static str,
    keys: &'static [Key<&'static str>],
    does: &'static str,
    action: fn(&mut App, &Press),
) -> Binding {
    Binding {
        label,
        keys,
        does,
        action,
    }
}

/// The key table, a slice per line of the help. A letter stands for itself in either case.
#[rustfmt::skip]
static KEYS: &[&[Binding]] = &[
    &[
        bind("arrows", ARROWS, "orbit (shift: pan)", arrow),
        bind("+ -", &[Ch("+"), Ch("="), Ch("-"), Ch("_")], "zoom", zoom),
        bind("C or Home", &[Named(NamedKey::Home), Ch("c")], "reset camera", reset_camera),
    ],
    &[
        bind("T / shift+T", &[Ch("t")], "next / previous tracer", next_tracer),
        bind("V", &[Ch("v")], "next grid variant", next_variant),
        bind("B", &[Ch("b")], "next BVH variant (sah, wagner)", next_bvh_variant),
    ],
    &[
        bind("G / shift+G", &[Ch("g")], "grid resolution +4 / -4", grid_step),
        bind("A", &[Ch("a")], "grid resolution auto", grid_auto),
    ],
    &[bind("] / [", &[Ch("]"), Ch("}"), Ch("["), Ch("{")], "reflection depth +1 / -1", refl)],
    &[bind("S / shift+S", &[Ch("s")], SOFT_SHADOWS, soft_shadows)],
    &[bind("L / shift+L", &[Ch("l")], LIGHT_SAMPLES, light_samples)],
    &[
        bind("R or F5", &[Named(NamedKey::F5), Ch("r")], "reload kernels", reload),
        bind("P", &[Ch("p")], "save a screenshot", screenshot),
        bind("space", &[Named(NamedKey::Space)], "pause", pause),
        bind("H", &[Named(NamedKey::F1), Ch("h")], "help", help),
        bind("Q or Esc", &[Named(NamedKey::Escape), Ch("q")], "quit", quit),
    ],
];

const ARROWS: &[Key<&str>] = &[
    Named(NamedKey::ArrowLeft),
    Named(NamedKey::ArrowRight),
    Named(NamedKey::ArrowUp),
    Named(NamedKey::ArrowDown),
];
const SOFT_SHADOWS: &str = "soft shadows next / previous (off, exact, linespace, linespace-dda)";
const LIGHT_SAMPLES: &str =
    "light samples +1 / -1 per axis (2x2 ... 10x10; S and L: [[area_light]] scenes)";

/// The controls, printed by `H` and at start: the mouse, then the key table.
pub fn controls() -> String {
    let lines: Vec<String> = KEYS
        .iter()
        .map(|line| {
            let items: Vec<String> = line
                .iter()
                .map(|b| format!("{} {}", b.label, b.does))
                .collect();
            items.join(" | ")
        })
        .collect();
    format!("{MOUSE}\nkeys:  {}", lines.join("\n       "))
}

/// The binding of `key`, if any.
fn binding(key: &Key<&str>) -> Option<&'static Binding> {
    let bound = |k: &Key<&str>| match (k, key) {
        (Ch(a), Ch(b)) => a.eq_ignore_ascii_case(b),
        _ => k == key,
    };
    KEYS.iter()
        .flat_map(|line| line.iter())
        .find(|b| b.keys.iter().any(bound))
}

impl App {
    /// A key event: the action of the pressed key's binding.
    pub(super) fn key(&mut self, event_loop: &ActiveEventLoop, event: KeyEvent) {
        if event.state != ElementState::Pressed {
            return;
        }
        let press = Press {
            key: event.logical_key.as_ref(),
            shift: self.input.modifiers.shift_key(),
            event_loop,
        };
        if let Some(b) = binding(&press.key) {
            (b.action)(self, &press);
        }
    }
}

/// The item after `current` in `items` (before it with `back`), cyclically.
fn step<T: Copy + PartialEq>(items: &[T], current: &T, back: bool) -> T {
    let i = items.iter().position(|x| x == current).unwrap_or(0);
    let n = items.len();
    items[if back { (i + n - 1) % n } else { (i + 1) % n }]
}

fn arrow(app: &mut App, press: &Press) {
    let Named(key) = press.key else { return };
    let c = &app.camera;
    let camera = match (key, press.shift) {
        (NamedKey::ArrowLeft, true) => orbit::pan(c, -0.05, 0.0),
        (NamedKey::ArrowRight, true) => orbit::pan(c, 0.05, 0.0),
        (NamedKey::ArrowUp, true) => orbit::pan(c, 0.0, -0.05),
        (NamedKey::ArrowDown, true) => orbit::pan(c, 0.0, 0.05),
        (NamedKey::ArrowLeft, false) => orbit::orbit(c, -5.0, 0.0),
        (NamedKey::ArrowRight, false) => orbit::orbit(c, 5.0, 0.0),
        (NamedKey::ArrowUp, false) => orbit::orbit(c, 0.0, 5.0),
        (NamedKey::ArrowDown, false) => orbit::orbit(c, 0.0, -5.0),
        _ => return,
    };
    app.move_camera(camera);
}

fn zoom(app: &mut App, press: &Press) {
    let closer = matches!(press.key, Ch("+") | Ch("="));
    let camera = orbit::zoom(&app.camera, if closer { 0.9 } else { 1.0 / 0.9 });
    app.move_camera(camera);
}

fn reset_camera(app: &mut App, _: &Press) {
    app.move_camera(app.scene.camera);
}

fn next_tracer(app: &mut App, press: &Press) {
    let kinds = TracerArg::value_variants();
    let design = &app.design;
    let next = step(kinds, &design.kind, press.shift);
    if design.shadows.is_some() {
        // from the soft shadows to the next ray tracer
        let rebuild = next != design.kind;
        let result = app.show_tracer(next, design.options.clone(), rebuild);
        app.report(
            format!("tracer {} (soft shadows off)", value_name(next)),
            result,
        );
    } else if kinds.len() == 1 {
        app.notice = Some(format!("{} is the only tracer", value_name(next)));
        app.update_title(true);
    } else {
        let what = format!("tracer {}", value_name(next));
        app.change(next, design.options.clone(), what);
    }
}

fn next_variant(app: &mut App, _: &Press) {
    let mut o = app.design.options.clone();
    let g = &mut o.args.grid;
    g.grid_variant = step(GridVariant::value_variants(), &g.grid_variant, false);
    let what = format!("grid variant {}", value_name(g.grid_variant));
    app.change_grid(o, what);
}

fn next_bvh_variant(app: &mut App, _: &Press) {
    let mut o = app.design.options.clone();
    let b = &mut o.args.bvh_variant;
    *b = step(BvhVariant::value_variants(), b, false);
    let what = format!("BVH variant {}", value_name(*b));
    app.change_for(TracerArg::Bvh, o, what);
}

fn grid_step(app: &mut App, press: &Press) {
    let design = &app.design;
    let current = (design.options.resolution())
        .or(design.grid_in_use)
        .unwrap_or(16);
    let next = if press.shift {
        current.saturating_sub(GRID_STEP).max(1)
    } else {
        current.saturating_add(GRID_STEP)
    };
    let mut o = design.options.clone();
    o.args.grid.grid = GridResolution::N(next);
    app.change_grid(o, format!("grid resolution {next}³"));
}

fn grid_auto(app: &mut App, _: &Press) {
    let mut o = app.design.options.clone();
    o.args.grid.grid = GridResolution::Auto;
    app.change_grid(o, "grid resolution auto".into());
}

fn refl(app: &mut App, press: &Press) {
    let up = matches!(press.key, Ch("]") | Ch("}"));
    let depth = app.design.options.refl_depth;
    let next = if up {
        (depth + 1).min(MAX_REFL_DEPTH)
    } else {
        depth.saturating_sub(1)
    };
    if next != depth {
        let mut o = app.design.options.clone();
        o.refl_depth = next;
        app.change(app.design.kind, o, format!("reflection depth {next}"));
    }
}

/// Off (the ray tracer), exact, linespace, linespace-dda.
fn soft_shadows(app: &mut App, press: &Press) {
    let mut cycle = vec![None];
    cycle.extend(ShadowMode::value_variants().iter().copied().map(Some));
    let next = step(&cycle, &app.design.shadows, press.shift);
    let design = &app.design;
    let (what, result) = match next {
        _ if design.no_soft.is_some() => ("soft shadows".to_string(), Err(design.no_soft_error())),
        None => (
            format!("soft shadows off: {} tracer", value_name(design.kind)),
            app.show_tracer(design.kind, design.options.clone(), false),
        ),
        Some(mode) => (
            format!(
                "soft shadows {} {}x{}",
                mode.name(),
                design.samples.0,
                design.samples.1
            ),
            app.show_soft(mode, design.samples),
        ),
    };
    app.report(what, result);
}

fn light_samples(app: &mut App, press: &Press) {
    let step = |n: u32| {
        if press.shift {
            if n > MIN_LIGHT_SAMPLES {
                n - 1
            } else {
                n
            }
        } else {
            (n + 1).clamp(MIN_LIGHT_SAMPLES, MAX_LIGHT_SAMPLES)
        }
    };
    let samples = app.design.samples;
    let next = (step(samples.0), step(samples.1));
    let what = format!("light samples {}x{}", next.0, next.1);
    if app.design.no_soft.is_some() {
        let e = app.design.no_soft_error();
        app.report("light samples".into(), Err(e));
    } else if next == samples {
        app.notice = Some(format!(
            "light samples {}x{}: the keys go from {MIN_LIGHT_SAMPLES}x{MIN_LIGHT_SAMPLES} to \
             {MAX_LIGHT_SAMPLES}x{MAX_LIGHT_SAMPLES}",
            next.0, next.1
        ));
        app.update_title(true);
    } else if let Some(mode) = app.design.shadows {
        let result = app.show_soft(mode, next);
        app.report(what, result);
    } else {
        app.design.samples = next;
        app.say(gpgpu_rt::outln!(
            "{what} (for the soft shadows; S shows them)"
        ));
        app.notice = None;
        app.update_title(true);
    }
}

/// P: save the frame as `gpgpu-rt-SCENE-NNN.png` in the working directory.
fn screenshot(app: &mut App, _: &Press) {
    app.screenshots += 1;
    let stem = app
        .scene
        .path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let path = format!("gpgpu-rt-{stem}-{:03}.png", app.screenshots);
    // never the window's size: drawn offscreen at the image's size
    let none = Viewport {
        x: 0,
        y: 0,
        width: 0,
        height: 0,
    };
    if let Err(e) = app.save_screenshot(path.as_ref(), none) {
        app.say(gpgpu_rt::errln!("screenshot failed: {e:#}"));
    }
    app.picture.dirty = true;
}

fn reload(app: &mut App, _: &Press) {
    app.reload(None);
}

fn help(app: &mut App, _: &Press) {
    app.say(gpgpu_rt::outln!("{}", controls()));
}

fn quit(_: &mut App, press: &Press) {
    press.event_loop.exit();
}

fn pause(app: &mut App, _: &Press) {
    app.picture.toggle_pause();
    app.update_title(true);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The help as it was written by hand before the table.
    const CONTROLS: &str = "\
mouse: left drag orbit | right/middle drag or shift+left drag pan | wheel zoom
keys:  arrows orbit (shift: pan) | + - zoom | C or Home reset camera
       T / shift+T next / previous tracer | V next grid variant | B next BVH variant (sah, wagner)
       G / shift+G grid resolution +4 / -4 | A grid resolution auto
       ] / [ reflection depth +1 / -1
       S / shift+S soft shadows next / previous (off, exact, linespace, linespace-dda)
       L / shift+L light samples +1 / -1 per axis (2x2 ... 10x10; S and L: [[area_light]] scenes)
       R or F5 reload kernels | P save a screenshot | space pause | H help | Q or Esc quit";

    #[test]
    fn the_help_comes_from_the_table_unchanged() {
        assert_eq!(controls(), CONTROLS);
    }

    #[test]
    fn every_key_finds_its_own_binding() {
        for b in KEYS.iter().flat_map(|line| line.iter()) {
            for k in b.keys {
                assert_eq!(binding(k).map(|f| f.label), Some(b.label), "{k:?}");
            }
        }
    }

    #[test]
    fn the_keys_are_those_of_before_the_table() {
        // the arms of the `match` that dispatched the keys before the table
        use NamedKey::*;
        let before: &[(&str, &[Key<&str>])] = &[
            ("Q or Esc", &[Named(Escape), Ch("q"), Ch("Q")]),
            (
                "arrows",
                &[
                    Named(ArrowLeft),
                    Named(ArrowRight),
                    Named(ArrowUp),
                    Named(ArrowDown),
                ],
            ),
            ("+ -", &[Ch("+"), Ch("="), Ch("-"), Ch("_")]),
            ("C or Home", &[Named(Home), Ch("c"), Ch("C")]),
            ("T / shift+T", &[Ch("t"), Ch("T")]),
            ("V", &[Ch("v"), Ch("V")]),
            // added with the BVH variants
            ("B", &[Ch("b"), Ch("B")]),
            ("G / shift+G", &[Ch("g"), Ch("G")]),
            ("A", &[Ch("a"), Ch("A")]),
            ("] / [", &[Ch("]"), Ch("}"), Ch("["), Ch("{")]),
            ("S / shift+S", &[Ch("s"), Ch("S")]),
            ("L / shift+L", &[Ch("l"), Ch("L")]),
            ("R or F5", &[Named(F5), Ch("r"), Ch("R")]),
            ("P", &[Ch("p"), Ch("P")]),
            ("space", &[Named(Space)]),
            ("H", &[Named(F1), Ch("h"), Ch("H")]),
        ];
        for (label, keys) in before {
            for key in *keys {
                assert_eq!(binding(key).map(|b| b.label), Some(*label), "{key:?}");
            }
        }
        let bound = KEYS.iter().flat_map(|line| line.iter());
        let letters = |b: &Binding| {
            b.keys
                .iter()
                .filter(|k| matches!(k, Ch(c) if c.chars().all(|c| c.is_ascii_alphabetic())))
                .count()
        };
        let keys: usize = bound.map(|b| b.keys.len() + letters(b)).sum();
        let matched: usize = before.iter().map(|(_, keys)| keys.len()).sum();
        assert_eq!(keys, matched, "a key the match did not have");
        for other in [Ch("x"), Ch("tt"), Ch("1"), Named(NamedKey::Enter)] {
            assert!(binding(&other).is_none(), "{other:?}");
        }
    }

    #[test]
    fn steps_go_round() {
        let items = [1, 2, 3];
        assert_eq!(step(&items, &3, false), 1);
        assert_eq!(step(&items, &1, true), 3);
        assert_eq!(step(&items, &2, true), 1);
    }
}
