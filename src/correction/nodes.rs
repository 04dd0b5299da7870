//! Interpolation in the aerosol family's AOT nodes, shared by the band-pair and dark-spectrum
//! fits ([`super::image`]).

/// Where the measured long-band aerosol signal lies in a model's table: up to three nodes and
/// their weights, so that any tabulated quantity at the model's τ is Σ wᵢ·vᵢ. `a_long[k]` is the
/// model's aerosol signal at the long band at node k (increasing with τ). Inside the table the
/// weights are the quadratic Lagrange basis in the signal itself over the three nearest nodes
/// (path radiance is close to, but not, linear in τ: a linear interpolation between AOT nodes
/// 0.1 and 0.2 left 3 % at 400 nm and 10 % at 665 nm in Rrs); beyond the last node the last
/// segment is extended; a signal at or below zero is τ = 0.
pub(super) fn locate(a_long: &[f64], measured: f64) -> [(usize, f64); 3] {
    let n = a_long.len();
    if measured <= 0.0 || n < 2 {
        return [(0, 1.0), (0, 0.0), (0, 0.0)];
    }
    if measured >= a_long[n - 1] || n == 2 {
        let (k0, k1) = (n - 2, n - 1);
        let span = a_long[k1] - a_long[k0];
        let f = if span > 0.0 { (measured - a_long[k0]) / span } else { 0.0 };
        return [(k0, 1.0 - f), (k1, f), (k1, 0.0)];
    }
    // The segment holding the signal, and its nearer neighbour as the third node.
    let k = (0..n - 1).find(|&k| measured <= a_long[k + 1]).unwrap_or(n - 2);
    let first = if k == 0 {
        0
    } else if k + 2 >= n {
        n - 3
    } else if measured - a_long[k] < a_long[k + 1] - measured {
        k - 1
    } else {
        k
    };
    let x = [a_long[first], a_long[first + 1], a_long[first + 2]];
    let basis = |i: usize| {
        let (j, l) = ((i + 1) % 3, (i + 2) % 3);
        (measured - x[j]) * (measured - x[l]) / ((x[i] - x[j]) * (x[i] - x[l]))
    };
    if (x[1] - x[0]) * (x[2] - x[1]) * (x[2] - x[0]) <= 0.0 {
        // Nodes not strictly increasing (a degenerate table): linear in the segment.
        let span = a_long[k + 1] - a_long[k];
        let f = if span > 0.0 { (measured - a_long[k]) / span } else { 0.0 };
        return [(k, 1.0 - f), (k + 1, f), (k + 1, 0.0)];
    }
    [(first, basis(0)), (first + 1, basis(1)), (first + 2, basis(2))]
}

/// Σ wᵢ·vᵢ of `value(k)` over the located nodes.
pub(super) fn weighted(nodes: &[(usize, f64); 3], value: impl Fn(usize) -> f64) -> f64 {
    nodes.iter().map(|&(k, w)| if w == 0.0 { 0.0 } else { w * value(k) }).sum()
}
