use nalgebra::{Matrix6, Vector6};
use std::hint::black_box;
use std::time::Instant;
fn main() {
    let m = Matrix6::from_fn(|i, j| {
        if i == j {
            3.0
        } else {
            ((i * 7 + j) as f64).sin()
        }
    });
    let n = 1_000_000;
    let t = Instant::now();
    for _ in 0..n {
        black_box(black_box(m).lu());
    }
    println!(
        "lu 6x6: {:.1} ns",
        t.elapsed().as_secs_f64() / n as f64 * 1e9
    );
    let t = Instant::now();
    for _ in 0..n {
        black_box(small_lu(black_box(m)));
    }
    println!(
        "small lu 6x6: {:.1} ns",
        t.elapsed().as_secs_f64() / n as f64 * 1e9
    );
    let lu = m.lu();
    let v = Vector6::from_element(1.0);
    let t = Instant::now();
    for _ in 0..n {
        black_box(lu.solve(black_box(&v)));
    }
    println!(
        "solve 6x6: {:.1} ns",
        t.elapsed().as_secs_f64() / n as f64 * 1e9
    );
    let t = Instant::now();
    for _ in 0..n {
        black_box(black_box(m) * black_box(m));
    }
    println!(
        "mul 6x6: {:.1} ns",
        t.elapsed().as_secs_f64() / n as f64 * 1e9
    );
    let t = Instant::now();
    for _ in 0..n {
        black_box(black_box(m) * black_box(v));
    }
    println!(
        "matvec 6x6: {:.1} ns",
        t.elapsed().as_secs_f64() / n as f64 * 1e9
    );
}

#[allow(dead_code)]
fn small_lu(mut a: Matrix6<f64>) -> (Matrix6<f64>, [usize; 6]) {
    let mut perm = [0; 6];
    for k in 0..6 {
        let mut p = k;
        let mut big = a[(k, k)].abs();
        for i in k + 1..6 {
            let v = a[(i, k)].abs();
            if v > big {
                big = v;
                p = i;
            }
        }
        perm[k] = p;
        if p != k {
            a.swap_rows(p, k);
        }
        let inv = 1.0 / a[(k, k)];
        for i in k + 1..6 {
            let f = a[(i, k)] * inv;
            a[(i, k)] = f;
            for j in k + 1..6 {
                let akj = a[(k, j)];
                a[(i, j)] -= f * akj;
            }
        }
    }
    (a, perm)
}
