"""Write aerosol_6sv_components.csv from 6SV 1.0B's basic-component subroutines.

Usage: python3 make_aerosol_6sv_components.py DIR > aerosol_6sv_components.csv, where DIR holds
DUST.f, WATE.f, OCEA.f and SOOT.f of 6SV 1.0B (as distributed in the Orfeo ToolBox,
Modules/ThirdParty/6S/src/6SV1.0B/, commit 18e581f4ff4b9c01e247be9b86d8fd62c49753a4). Each file
holds, at 6SV's 20 wavelengths, the component's Mie asymmetry parameter (asy_m), extinction and
scattering coefficients (ex_m, sc_m), the phase function at 6SV's 83 quadrature angles (PHR),
and its volume per particle (vi_m). The values are copied, not changed.
"""
import re
import sys

WAVELENGTHS_NM = [350, 400, 412, 443, 470, 488, 515, 550, 590, 633, 670, 694, 760, 860, 1240,
                  1536, 1650, 1950, 2250, 3750]
COMPONENTS = [("dust_like", "DUST.f"), ("water_soluble", "WATE.f"), ("oceanic", "OCEA.f"),
              ("soot", "SOOT.f")]
NUMBER = r"[-+]?\d*\.\d+(?:[EeDd][-+]?\d+)?"


def data_block(text, head):
    """The numbers of the DATA statement starting with `head` (case-insensitive)."""
    start = text.lower().index(head.lower())
    body = text[start + len(head):]
    body = body[body.index("/") + 1:]
    body = body[:body.index("/")]
    return [float(v.replace("D", "E").replace("d", "e")) for v in re.findall(NUMBER, body)]


def component(path):
    text = open(path).read()
    # Fortran continuation marks in column 6 are not data.
    lines = [l[6:] if len(l) > 6 and l[:5].strip() == "" and l[5] not in " 0" else l
             for l in text.splitlines()]
    text = "\n".join(l for l in lines if not l[:1] in ("c", "C"))
    asy = data_block(text, "data (asy_m(j),j=1,20)")
    pairs = data_block(text, "data (ex_m(j),sc_m(j),j=1,20)")
    ext, sca = pairs[0::2], pairs[1::2]
    phase = [data_block(text, f"DATA ((PHR(i,j),j=1,83),i={i:2d},{i:2d})") for i in range(1, 21)]
    vi = float(re.search(r"vi_m\s*=\s*(" + NUMBER + ")", text).group(1).replace("D", "E"))
    assert len(asy) == len(ext) == len(sca) == 20 and all(len(p) == 83 for p in phase), path
    return asy, ext, sca, phase, vi


def main(folder):
    print("# name: 6SV 1.0B basic aerosol components (dust-like, water-soluble, oceanic, soot): extinction and scattering coefficients, asymmetry parameter, volume per particle and phase function at 20 wavelengths")
    print("# units: wavelength_nm: nm; ext, sca: extinction and scattering coefficients as 6SV tabulates them (km-1 for the component's reference number density; only their ratios enter a mixture); asy: dimensionless; vi: 6SV's volume per particle (mixing weight c_i/v_i); p_1..p_83: phase function at 6SV's 83 quadrature cosines (mu_1 = -1, mu_2..mu_41 the negative nodes of the 80-point Gauss-Legendre rule, mu_42 = 0, mu_43..mu_82 the positive nodes, mu_83 = 1), normalised as 6SV does ((1/2) int P dmu = 1 over its quadrature)")
    print("# source: 6SV 1.0B subroutines DUST.f, WATE.f, OCEA.f, SOOT.f (data statements asy_m, ex_m, sc_m, PHR and vi_m), as distributed in the Orfeo ToolBox (github.com/orfeotoolbox/OTB, Modules/ThirdParty/6S/src/6SV1.0B/, commit 18e581f4ff4b9c01e247be9b86d8fd62c49753a4); extracted by make_aerosol_6sv_components.py")
    print("# citation: Vermote, E. F. et al. (1997) IEEE TGRS 35, 675-686 (6S); Kotchenova, S. Y. et al. (2006) Appl. Opt. 45, 6762-6774 (6SV); component parameters and refractive indices from d'Almeida, G. A., Koepke, P. and Shettle, E. P. (1991) Atmospheric Aerosols: Global Climatology and Radiative Characteristics (the files' own citation)")
    print("# license: data values of the 6SV code (free distribution); cite the above")
    print("# processing: values copied unchanged; the mixture rule is 6SV's AEROSO.f: c_ij = (c_i/v_i)/sum(c_j/v_j), ext = sum c_ij ext_i, sca = sum c_ij sca_i, P = sum c_ij sca_i P_i / sca")
    print(",".join(["component", "wavelength_nm", "ext", "sca", "asy", "vi"] + [f"p_{k}" for k in range(1, 84)]))
    for key, name in COMPONENTS:
        asy, ext, sca, phase, vi = component(f"{folder}/{name}")
        for l, w in enumerate(WAVELENGTHS_NM):
            cells = [key, str(w), f"{ext[l]:.7e}", f"{sca[l]:.7e}", f"{asy[l]:.3f}", f"{vi:.9e}"]
            cells += [f"{p:.4e}" for p in phase[l]]
            print(",".join(cells))


if __name__ == "__main__":
    main(sys.argv[1])
