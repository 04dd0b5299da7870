use shoal::atmosphere::*;
use shoal::spectral::Table;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let acc = RtAccuracy::preset(args.get(1).map(String::as_str).unwrap_or("default")).unwrap();
    let pol = args.get(2).map(|s| s == "pol").unwrap_or(true);
    let acc = RtAccuracy {
        polarization_correction: pol,
        ..acc
    };
    let t = Table::from_file(std::path::Path::new("tests/data/osoaa/path_compare.csv")).unwrap();
    let wl = t.column_f64("wl_nm").unwrap();
    let sza = t.column_f64("sza").unwrap();
    let vza = t.column_f64("vza").unwrap();
    let aer = t.column_str("aer").unwrap();
    let tau_r = t.column_f64("tau_ray_osoaa").unwrap();
    let vec = t.column_f64("rho_osoaa_vec_flat").unwrap();
    let scal = t.column_f64("rho_osoaa_scal_flat").unwrap();
    let td = t.column_f64("t_down_osoaa_flat").unwrap();
    let t0 = std::time::Instant::now();
    let mut worst = (0.0f64, 0.0f64);
    for i in 0..t.len() {
        let kind = AerosolType::parse(aer[i]).unwrap();
        let aerosol = mixture_optics(kind, wl[i])
            .unwrap()
            .map(|o| (0.1 * o.extinction_ratio, o.ssa, o.phase));
        let col = WavelengthColumn {
            wavelength_nm: wl[i],
            tau_rayleigh: tau_r[i],
            depolarization: AIR_DEPOLARIZATION,
            aerosol,
            rayleigh_scale_height_km: 8.0,
            aerosol_scale_height_km: 2.0,
            water_index: 1.34,
        };
        let mu0 = sza[i].to_radians().cos();
        let muv = vza[i].to_radians().cos();
        let s = solve_sun(&col, mu0, &[muv], &acc);
        let rho = std::f64::consts::PI * s.radiance(0, 90f64.to_radians()) / mu0;
        let reference = if pol { vec[i] } else { scal[i] };
        let e = 100.0 * (rho / reference - 1.0);
        let etd = 100.0 * (s.ed() / mu0 / td[i] - 1.0);
        worst.0 = worst.0.max(e.abs());
        worst.1 = worst.1.max(etd.abs());
        println!(
            "{:6.1} sza{:3.0} vza{:3.0} {:12} rho {:.6} ref {:.6} err {:+6.2}%  tdown {:.5} ref {:.5} err {:+5.2}% orders {}",
            wl[i],
            sza[i],
            vza[i],
            aer[i],
            rho,
            reference,
            e,
            s.ed() / mu0,
            td[i],
            etd,
            s.orders
        );
    }
    println!(
        "worst rho {:.2}% tdown {:.2}%  time {:.3}s",
        worst.0,
        worst.1,
        t0.elapsed().as_secs_f64()
    );
}
