//! What the central panel says before its maps: a scene the retrieval does not suit (and the
//! switch to the one that does), a product the retrieval does not make, and a run of the
//! configuration set that failed (its reason in full where its maps would be, and the way out).

use super::ShoalApp;
use super::model::ProductKind;
use crate::retrieval::algorithm::{ALMI, SAMBUCA};

/// The scene ↔ retrieval banner: a scene whose bottom shows needs a retrieval that models one.
pub(super) fn retrieval_banner(app: &mut ShoalApp, ui: &mut egui::Ui) {
    use super::logic::UiCommand;
    if app.state.runs(ALMI.name) && app.state.scene.needs_bottom_model() {
        ui.horizontal_wrapped(|ui| {
            ui.colored_label(
                super::theme::NOTICE,
                format!(
                    "`{}` has a visible bottom (its depth map is shallow). aLMI assumes optically deep water: its \
                     concentrations are biased by the bottom, and it retrieves no depth or substrate.",
                    app.state.scene_name
                ),
            );
            if ui
                .button(format!("Use {}", SAMBUCA.title))
                .on_hover_text("Retrieve depth, substrate and water together")
                .clicked()
            {
                app.ui.commands.push(UiCommand::UseRetrieval(SAMBUCA.name));
            }
        });
    }
}

/// A product every design misses by more than this (log-space MAE, Seegers et al. 2018: off by
/// a factor of 3 on average) is the retrieval's error over the scene, not the instruments': over
/// Lake Hume the noise-limited CubeSat misses NAP by 87 % while the SmallSat makes 12 %, and no
/// design reaches 200 % even at a 1/16 preview; over `clear_water` aLMI misses chl-a by thousands.
const OUT_OF_DOMAIN_MAE_PCT: f64 = 200.0;

/// The retrieval out of its domain: a product that every design returning it misses by more than
/// [`OUT_OF_DOMAIN_MAE_PCT`] (aLMI over `clear_water` showed chl-a at 5131 % with nothing said),
/// named with each design's error, so nobody reads it as the instruments'.
pub(super) fn domain_banner(app: &ShoalApp, ui: &mut egui::Ui) {
    let runs: Vec<(usize, &crate::metrics::ProductMetrics)> = (0..app.state.designs.len())
        .filter_map(|i| Some((i, &app.link.current(i)?.output.retrievals.first()?.metrics)))
        .collect();
    let mut variables: Vec<&str> = Vec::new();
    for (_, m) in &runs {
        for v in &m.variables {
            if !variables.contains(&v.variable.as_str()) {
                variables.push(&v.variable);
            }
        }
    }
    let mut missed = Vec::new();
    for variable in variables {
        let errors: Vec<(usize, f64)> =
            runs.iter().filter_map(|(i, m)| m.get(variable).filter(|v| v.n > 0).map(|v| (*i, v.mae_pct()))).collect();
        if !errors.is_empty() && errors.iter().all(|(_, e)| *e > OUT_OF_DOMAIN_MAE_PCT) {
            let each: Vec<String> = errors
                .iter()
                .map(|(i, e)| format!("{} {} %", super::model::label(*i), super::legend::format_value(*e)))
                .collect();
            missed.push(format!("{} {}", crate::metrics::name(variable), each.join(", ")));
        }
    }
    if missed.is_empty() {
        return;
    }
    let retrieval = retrieval_name(&app.state);
    ui.add(
        egui::Label::new(
            egui::RichText::new(format!(
                "{retrieval} is off by more than {OUT_OF_DOMAIN_MAE_PCT:.0} % for every design that returned it ({}): over `{}` \
                 the retrieval, not the instruments, sets this error (its model does not fit the scene's water). \
                 Compare designs on what it retrieves well, or choose a retrieval made for this water.",
                missed.join("; "),
                app.state.scene_name
            ))
            .color(super::theme::NOTICE),
        )
        .wrap(),
    );
}

/// The retrieval's name as tables and captions show it.
pub(super) fn retrieval_name(state: &super::model::AppState) -> String {
    state.retrieval_spec().title().to_string()
}

/// What the shown product is when the retrieval does not make it.
pub(super) fn product_note(app: &ShoalApp) -> Option<String> {
    let spec = app.state.retrieval_spec();
    let retrieval = spec.title();
    let missing = match app.state.product {
        ProductKind::Depth | ProductKind::Chl | ProductKind::Nap | ProductKind::Cdom | ProductKind::Extra(_) => {
            app.state.product.variable().is_some_and(|v| !spec.algorithm().variables().iter().any(|p| p == v))
        }
        // Classes only the retrievals that choose them make.
        ProductKind::Substrate => !spec.algorithm().classes().substrates,
        ProductKind::SiopSet => !spec.algorithm().classes().siop_sets,
        ProductKind::Rrs | ProductKind::Level1 | ProductKind::Snr => false,
    };
    missing.then(|| {
        let label = app.state.product.label();
        let product = label.split(" (").next().unwrap_or_default();
        format!("{retrieval} does not retrieve the {product}: no design has a map of it.")
    })
}

/// Where design `index`'s maps would be when its run of the configuration set failed: the
/// reason in full, and the way out when Shoal knows one.
pub(super) fn failure_box(app: &mut ShoalApp, ui: &mut egui::Ui, index: usize, message: &str) {
    use super::logic::UiCommand;
    let ab = super::model::label(index);
    egui::Frame::group(ui.style()).stroke(egui::Stroke::new(1.5, super::theme::FAIL)).show(ui, |ui| {
        ui.set_width(ui.available_width());
        ui.colored_label(
            super::theme::FAIL,
            format!("{ab}: the run of the configuration set failed — nothing of {ab} is shown."),
        );
        ui.add(egui::Label::new(message).wrap());
        let deep = !app.state.scene.needs_bottom_model();
        if app.state.runs(SAMBUCA.name) && deep {
            ui.horizontal_wrapped(|ui| {
                ui.label(format!(
                    "`{}` is optically deep: SAMBUCA fits a bottom it does not have.",
                    app.state.scene_name
                ));
                if ui
                    .button(format!("Use {}", ALMI.title))
                    .on_hover_text("Retrieve chl-a, NAP and CDOM for deep water")
                    .clicked()
                {
                    app.ui.commands.push(UiCommand::UseRetrieval(ALMI.name));
                }
            });
        }
    });
}

/// An external retrieval runs a program the study names: ask before it runs, and say why it
/// returned nothing when it failed (the rest of the run is shown as usual).
pub(super) fn external_banner(app: &mut ShoalApp, ui: &mut egui::Ui) {
    use crate::retrieval::external;
    let crate::retrieval::RetrievalSpec::External(spec) = app.state.retrieval_spec() else { return };
    if !spec.may_run() {
        ui.horizontal_wrapped(|ui| {
            ui.colored_label(
                super::theme::NOTICE,
                format!(
                    "The retrieval `{}` runs a program on your machine: `{}`. Nothing runs until you allow it.",
                    spec.name,
                    spec.command.join(" ")
                ),
            );
            if ui.button("Allow this program").on_hover_text("For this session only; never saved").clicked() {
                external::allow(&spec.command);
                app.link.refine();
            }
        });
        return;
    }
    let failure = (0..app.state.designs.len()).find_map(|i| match app.link.standing(i) {
        super::link::Standing::Current(s) => s.output.retrievals.first().and_then(|r| r.failure.clone()),
        _ => None,
    });
    if let Some(message) = failure {
        egui::Frame::group(ui.style()).stroke(egui::Stroke::new(1.5, super::theme::FAIL)).show(ui, |ui| {
            ui.set_width(ui.available_width());
            ui.colored_label(super::theme::FAIL, format!("`{}` returned nothing.", spec.name));
            ui.add(egui::Label::new(egui::RichText::new(message).monospace()).wrap());
        });
    }
}
