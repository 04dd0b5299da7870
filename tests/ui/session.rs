//! The saved session across starts: a fresh start (`--fresh`, `--screenshot`) neither reads nor
//! writes it, a second window does not overwrite the first one's, and the window that owns it
//! saves it.

use std::path::Path;

use eframe::App as _;
use egui_kittest::Harness;
use shoal::app::model::AppState;
use shoal::app::{AppOptions, ShoalApp};

/// eframe's storage, unused: the session goes to Shoal's own file.
struct NoStorage;

impl eframe::Storage for NoStorage {
    fn get_string(&self, _key: &str) -> Option<String> {
        None
    }
    fn set_string(&mut self, _key: &str, _value: String) {}
    fn remove_string(&mut self, _key: &str) {}
    fn flush(&mut self) {}
}

/// The app as `shoal app` starts it, with its Shoal folder at `home`.
fn start(home: &Path, fresh: bool) -> Harness<'static, ShoalApp> {
    let options = AppOptions { engine_threads: 1, fresh, home: Some(home.to_path_buf()), ..AppOptions::default() };
    Harness::builder().with_size(egui::vec2(1280.0, 720.0)).build_eframe(move |cc| ShoalApp::new(cc, options))
}

/// Edit A's aperture and save as eframe does on quit; the app is dropped (which waits for the
/// write) when the harness goes.
fn edit_and_quit(mut h: Harness<'static, ShoalApp>, aperture_mm: f64) {
    h.step();
    h.state_mut().state.designs[0].spec.aperture_mm = aperture_mm;
    h.state_mut().save(&mut NoStorage);
}

#[test]
fn fresh_starts_and_a_second_window_never_overwrite_the_saved_session() {
    let home = super::temp_library("session-home");
    let session = home.join("session.ron");
    let mut saved = AppState::default();
    saved.designs[0].spec.aperture_mm = 77.0;
    let text = ron::to_string(&saved).unwrap();
    std::fs::write(&session, &text).unwrap();

    // A fresh start shows the default study and leaves the session as it was.
    let mut h = start(&home, true);
    h.step();
    assert_eq!(h.state().state.designs[0].spec.aperture_mm, AppState::default().designs[0].spec.aperture_mm);
    edit_and_quit(h, 99.0);
    assert_eq!(std::fs::read_to_string(&session).unwrap(), text, "--fresh wrote the session");

    // A second window (another running process holds the lock: PID 1 always runs) reads the
    // session, says it will not save it, and does not.
    std::fs::write(home.join("session.lock"), "1").unwrap();
    let mut h = start(&home, false);
    h.step();
    assert_eq!(h.state().state.designs[0].spec.aperture_mm, 77.0, "the session is read");
    let error = h.state().error().unwrap_or_default().to_string();
    assert!(error.contains("another Shoal window") && error.contains("will not save"), "{error}");
    edit_and_quit(h, 99.0);
    assert_eq!(std::fs::read_to_string(&session).unwrap(), text, "the second window wrote the session");

    // The owner saves, and lets the lock go when it closes.
    std::fs::remove_file(home.join("session.lock")).unwrap();
    edit_and_quit(start(&home, false), 88.0);
    let back: AppState = ron::from_str(&std::fs::read_to_string(&session).unwrap()).unwrap();
    assert_eq!(back.designs[0].spec.aperture_mm, 88.0);
    assert!(!home.join("session.lock").exists(), "the lock outlived the window");
    let _ = std::fs::remove_dir_all(&home);
}

/// Sessions saved by earlier Shoals (tests/data/sessions, verbatim): A and B as fields `a` and
/// `b`, before and after `schema_version` existed. Today's app reads them as designs A and B,
/// keeps everything else, and saves them in today's format.
#[test]
fn sessions_saved_by_earlier_shoals_still_load() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/sessions");
    for (file, scene, retrieval_name) in
        [("session_v1.ron", "lake_hume_bloom", "oc4"), ("session_v2.ron", "lake_hume_haze", "mine")]
    {
        let home = super::temp_library(&format!("old-{file}"));
        std::fs::copy(data.join(file), home.join("session.ron")).unwrap();
        let mut h = start(&home, false);
        h.step();
        let app = h.state();
        assert_eq!(app.error(), None, "{file}: read without complaint");
        let s = &app.state;
        assert_eq!(s.designs.len(), 2, "{file}: A and B became two designs");
        assert_eq!(s.designs[0].preset, "cubesat", "{file}");
        assert_eq!((s.scene_name.as_str(), s.editing, s.on_maps.as_slice(), s.pair), (scene, 0, &[0, 1][..], [0, 1]));
        let kept = s.retrievals.get(2).map(|r| r.name().to_string());
        assert_eq!(kept.as_deref(), Some(retrieval_name), "{file}: the rest is kept");
        let b = s.designs[1].preset.clone();
        // Saved again, it is today's format and reads back the same.
        h.state_mut().save(&mut NoStorage);
        drop(h);
        let text = std::fs::read_to_string(home.join("session.ron")).unwrap();
        assert!(text.contains("designs:") && !text.contains("editing_instrument"), "{file}: {text}");
        assert!(text.contains(&format!("schema_version: {}", shoal::schema::VERSION)));
        let mut back: AppState = ron::from_str(&text).unwrap();
        back.settle();
        assert_eq!(back.designs[1].preset, b);
        let _ = std::fs::remove_dir_all(&home);
    }
}
