use super::BlockMeans;

/// The block means as they were first written: a copy of the cube, each coarse band's value the
/// mean of its block, summed over the grid in row-major order, one band at a time.
fn spread_means(block: &[usize], radiance: &[f32], (lines, detectors): (&[usize], &[usize]), cols: usize) -> Vec<f32> {
    let nb = block.len();
    let rows = radiance.len() / (cols * nb);
    let mut out = radiance.to_vec();
    // The block ids as the table numbers them (what is tested is the sums and the lookup).
    let dense = super::block_ids;
    for b in (0..nb).filter(|&b| block[b] > 1) {
        let k = block[b];
        let (row_id, _) = dense(&lines[..rows], k);
        let (col_id, n_c) = dense(&detectors[..cols], k);
        let blocks = (row_id[rows - 1] + 1) * n_c;
        let (mut sum, mut count) = (vec![0.0f64; blocks], vec![0u32; blocks]);
        for r in 0..rows {
            for c in 0..cols {
                let i = row_id[r] * n_c + col_id[c];
                sum[i] += f64::from(radiance[(r * cols + c) * nb + b]);
                count[i] += 1;
            }
        }
        for r in 0..rows {
            for c in 0..cols {
                let i = row_id[r] * n_c + col_id[c];
                out[(r * cols + c) * nb + b] = (sum[i] / f64::from(count[i].max(1))) as f32;
            }
        }
    }
    out
}

/// The table gives every pixel of every band what the spread copy held, bit for bit, on one
/// thread and on three: grid bands their own value, coarse ones their block's mean, with partial
/// blocks at the edges and every other line and detector simulated (a decimated grid).
#[test]
fn block_means_match_the_spread_copy_bit_for_bit() {
    let (rows, cols) = (23, 31);
    let block = [1, 2, 6, 1, 3, 2];
    let nb = block.len();
    let radiance: Vec<f32> =
        (0..rows * cols * nb).map(|i| 1.0 + ((i * 7919) % 1013) as f32 * 0.37 + (i % 7) as f32 * 1e-3).collect();
    for step in [1, 2] {
        let lines: Vec<usize> = (0..rows).map(|r| 5 + r * step).collect();
        let detectors: Vec<usize> = (0..cols).map(|c| c * step).collect();
        let expected = spread_means(&block, &radiance, (&lines, &detectors), cols);
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let means = pool.install(|| BlockMeans::new(&block, &radiance, (&lines, &detectors), cols)).unwrap();
            for r in 0..rows {
                for c in 0..cols {
                    for (b, want) in expected[(r * cols + c) * nb..(r * cols + c + 1) * nb].iter().enumerate() {
                        let own = radiance[(r * cols + c) * nb + b];
                        let got = means.value(r, c, b, own);
                        assert_eq!(
                            got.to_bits(),
                            want.to_bits(),
                            "pixel ({r}, {c}), band {b}, step {step}, {threads} threads"
                        );
                    }
                }
            }
        }
    }
    assert!(
        BlockMeans::new(&[1, 1], &radiance[..2 * cols * 2], (&[0, 1], &(0..cols).collect::<Vec<_>>()), cols).is_none()
    );
}
