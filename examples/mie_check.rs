use shoal::atmosphere::*;
fn main() {
    let ppd: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(0);
    let grid = if ppd == 0 {
        SizeGrid::Osoaa
    } else {
        SizeGrid::Log(ppd)
    };
    let t0 = std::time::Instant::now();
    let mut cache = std::collections::HashMap::new();
    for w in [400.0, 550.0, 865.4] {
        for c in Component::ALL {
            let t = std::time::Instant::now();
            let o = compute_component(c, w, grid);
            let p = PhaseFunction::from_table(&table_angles_deg(), &o.p11).unwrap();
            println!(
                "{w} {:?} cext {:.6e} csca {:.6e} ssa {:.5} g {:.5} ({:.2}s)",
                c,
                o.c_ext_um2,
                o.c_sca_um2,
                o.c_sca_um2 / o.c_ext_um2,
                p.asymmetry(),
                t.elapsed().as_secs_f64()
            );
            cache.insert((c.key(), w as i64), o);
        }
    }
    for kind in [AerosolType::Continental, AerosolType::Maritime] {
        let k = |w: f64| -> (f64, f64) {
            let mut e = 0.0;
            let mut s = 0.0;
            for (c, n) in kind.number_fractions() {
                let o = &cache[&(c.key(), w as i64)];
                e += n * o.c_ext_um2;
                s += n * o.c_sca_um2;
            }
            (e, s)
        };
        let (e550, s550) = k(550.0);
        println!(
            "{kind:?}: ssa550 {:.4} ratio400 {:.5} ratio865 {:.5}",
            s550 / e550,
            k(400.0).0 / e550,
            k(865.4).0 / e550
        );
    }
    println!("total {:.1}s", t0.elapsed().as_secs_f64());
}
