//! Design search against an exhaustive grid at a reduced resolution (issue #39): the search's
//! cheapest feasible design costs at most 5 % more than the grid's, with at most a tenth of the
//! grid's runs; a requirement no design meets is answered with the closest design.

use shoal::control::RunControl;
use shoal::design::{Dimension, Evaluator, Settings, cheapest_feasible, search, search_from};
use shoal::engine::Engine;
use shoal::study::{Requirements, ResolvedStudy, StudySpec};

const APERTURES: usize = 25;
const EXPOSURES: usize = 8;

/// The design study with one seed (the grid stays affordable in a test; the search sees the
/// same seed), edited by `edit` before it is resolved.
struct Fixture {
    spec: StudySpec,
    resolved: ResolvedStudy,
    requirements: Requirements,
}

impl Fixture {
    fn new(edit: impl FnOnce(&mut StudySpec)) -> Self {
        let mut spec = StudySpec::preset("cubesat_design_lake_hume").unwrap();
        spec.seeds = vec![1];
        edit(&mut spec);
        let resolved = spec.resolve(None).unwrap();
        let requirements = spec.requirements.clone().unwrap();
        Self { spec, resolved, requirements }
    }

    /// The evaluator over `vars` at decimation 8, from the study's instrument.
    fn evaluator<'a>(&'a self, vars: &'a [Dimension]) -> Evaluator<'a> {
        Evaluator {
            base: &self.resolved.runs[0].2,
            vars,
            seeds: &self.spec.seeds,
            requirements: &self.requirements,
            budgets: &self.resolved.budgets,
            decimation: 8,
        }
    }
}

/// `evaluations` designs at decimation 8 from optimiser seed `seed`, no confirmation.
fn settings(evaluations: usize, seed: u64) -> Settings {
    Settings { confirm_decimation: None, seed, ..Settings::new(evaluations, 8) }
}

#[test]
fn the_search_finds_the_grids_cheapest_feasible_design_with_a_tenth_of_the_runs() {
    let fixture = Fixture::new(|_| {});
    let vars = [Dimension::parse("aperture_mm=40:200").unwrap(), Dimension::parse("exposure_s=0.0005:0.003").unwrap()];
    let evaluator = fixture.evaluator(&vars);
    let control = RunControl::default();
    // The grid: every combination of 25 apertures and 8 exposures, 200 runs.
    let mut engine = Engine::new();
    let mut grid = Vec::new();
    for i in 0..APERTURES {
        for j in 0..EXPOSURES {
            let x =
                [40.0 + 160.0 * i as f64 / (APERTURES - 1) as f64, 0.0005 + 0.0025 * j as f64 / (EXPOSURES - 1) as f64];
            grid.push(evaluator.evaluate(&mut engine, &x, &control).unwrap());
        }
    }
    let best = &grid[cheapest_feasible(&grid).expect("the grid has a feasible design")];
    let budget = APERTURES * EXPOSURES / 10;
    let settings = settings(budget, 1);
    let found = search(&evaluator, &settings, &control, |_, _, _| {}).unwrap();
    let answer = found.answer().expect("the search finds a feasible design");
    assert!(found.evaluations.len() <= budget, "{} runs", found.evaluations.len());
    let (grid_cost, search_cost) = (best.cost.unwrap(), answer.cost.unwrap());
    assert!(
        search_cost <= 1.05 * grid_cost,
        "search {search_cost:.4} at {:?} vs grid {grid_cost:.4} at {:?}",
        answer.x,
        best.x
    );
    assert!(answer.feasible() && answer.constraints.iter().all(|(_, g)| *g <= 0.0));
    eprintln!(
        "grid: {} runs, cheapest feasible {grid_cost:.4} at {:?}; search: {} runs, {search_cost:.4} at {:?}",
        grid.len(),
        best.x,
        found.evaluations.len(),
        answer.x
    );
}

#[test]
fn a_requirement_no_design_meets_names_the_closest() {
    let fixture = Fixture::new(|spec| spec.requirements.as_mut().unwrap().products[0].mae_pct = Some(0.5));
    let vars = [Dimension::parse("aperture_mm=40:120").unwrap()];
    let evaluator = fixture.evaluator(&vars);
    let settings = settings(5, 2);
    let found = search(&evaluator, &settings, &RunControl::default(), |_, _, _| {}).unwrap();
    assert!(found.answer().is_none());
    let closest = &found.evaluations[found.closest.expect("a closest design")];
    // The closest misses by the least. Every design misses 0.5 % by far more than any other
    // limit, so the closest is the one with the smallest chl-a error (from its metrics).
    let chl = closest.constraints.iter().find(|(k, _)| k.starts_with("chl_mg_m3")).unwrap().1;
    assert!(chl > 1.0, "{chl}");
    let mae = |e: &shoal::design::Evaluation| e.mae_pct.iter().find(|(v, _)| v == "chl_mg_m3").unwrap().1;
    assert!(found.evaluations.iter().all(|e| mae(e) >= mae(closest)), "closest at {:?}", closest.x);
}

#[test]
fn a_cost_model_that_refuses_the_range_is_refused_before_any_run() {
    let fixture = Fixture::new(|spec| spec.budgets = Some(shoal::study::Source::Preset("default".into())));
    let vars = [Dimension::parse("aperture_mm=40:200").unwrap()];
    let evaluator = fixture.evaluator(&vars);
    let settings = settings(5, 1);
    let e = shoal::design::check(&evaluator, &settings).unwrap_err().to_string();
    assert!(e.contains("budgets.cost.out_of_range") && e.contains("0.3–6.5 m"), "{e}");
}

#[test]
fn a_search_resumed_from_two_shards_of_its_start_is_the_search_run_whole() {
    let fixture = Fixture::new(|_| {});
    let vars = [Dimension::parse("aperture_mm=40:200").unwrap(), Dimension::parse("exposure_s=0.0005:0.003").unwrap()];
    let evaluator = fixture.evaluator(&vars);
    let control = RunControl::default();
    let whole = settings(9, 1);
    let once = search(&evaluator, &whole, &control, |_, _, _| {}).unwrap();
    // The start (5 designs) in two shards, as two jobs of a cluster would run it.
    let mut prior = Vec::new();
    for i in 0..2 {
        let shard = Settings { shard: Some(shoal::sweep::Shard { index: i, count: 2 }), ..whole.clone() };
        let part = search(&evaluator, &shard, &control, |_, _, _| {}).unwrap();
        assert_eq!(part.evaluations.len(), if i == 0 { 3 } else { 2 });
        prior.extend(part.evaluations);
    }
    let mut fresh = 0;
    let resumed = search_from(&evaluator, &whole, &prior, &control, |e, _, _| {
        fresh += usize::from(!prior.iter().any(|p| p.x == e.x));
    })
    .unwrap();
    assert_eq!(fresh, 4, "only the four designs after the start run again");
    let xs = |s: &shoal::design::Search| s.evaluations.iter().map(|e| e.x.clone()).collect::<Vec<_>>();
    assert_eq!(xs(&resumed), xs(&once), "the same designs in the same order");
    assert_eq!(resumed.cheapest, once.cheapest);
}
