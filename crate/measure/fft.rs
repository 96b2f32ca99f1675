//! A real and complex discrete Fourier transform of any length, written here so the crate keeps
//! to its few dependencies: iterative radix-2 Cooley–Tukey for powers of two, and Bluestein's
//! chirp-z algorithm (a power-of-two convolution) for every other length.
//!
//! X_k = Σₙ xₙ e^{−2πi kn/N} (the sign and scaling of numpy's `fft.fft`). Plans precompute the
//! twiddles and the bit-reversal table, so a Welch estimate reuses one plan for every segment.
//! Accuracy: the twiddles are computed directly (not by recurrence), so the round-off error
//! grows like O(ε log N); tests compare with the O(N²) definition.

use std::f64::consts::PI;

/// A complex number `re + i·im`: nalgebra's (num-complex's), the one the rest of the crate
/// uses too. Its product, conjugate, |z|² and e^{iθ} (`cis`) are the same formulas the plans
/// need.
pub type Complex = nalgebra::Complex<f64>;

/// Radix-2 plan: twiddles e^{−2πik/N} for k < N/2 and the bit-reversal permutation.
#[derive(Debug, Clone)]
struct Radix2 {
    n: usize,
    twiddles: Vec<Complex>,
    reversed: Vec<u32>,
}

impl Radix2 {
    fn new(n: usize) -> Self {
        debug_assert!(n.is_power_of_two());
        let bits = n.trailing_zeros();
        let twiddles = (0..n / 2)
            .map(|k| Complex::cis(-2.0 * PI * k as f64 / n as f64))
            .collect();
        let reversed = (0..n as u32)
            .map(|i| {
                if bits == 0 {
                    0
                } else {
                    i.reverse_bits() >> (32 - bits)
                }
            })
            .collect();
        Radix2 {
            n,
            twiddles,
            reversed,
        }
    }

    /// In-place forward transform of `data` (length `n`).
    fn forward(&self, data: &mut [Complex]) {
        let n = self.n;
        for i in 0..n {
            let j = self.reversed[i] as usize;
            if j > i {
                data.swap(i, j);
            }
        }
        let mut half = 1;
        while half < n {
            let stride = n / (2 * half);
            for start in (0..n).step_by(2 * half) {
                let (lo, hi) = data[start..start + 2 * half].split_at_mut(half);
                for k in 0..half {
                    let t = hi[k] * self.twiddles[k * stride];
                    hi[k] = lo[k] - t;
                    lo[k] += t;
                }
            }
            half *= 2;
        }
    }
}

/// Bluestein plan for a length `n` that is not a power of two: X[k] = b̄ₖ Σ (xₙ b̄ₙ) b_{k−n},
/// bₙ = e^{iπn²/N}, the convolution done with radix-2 transforms of length m ≥ 2n − 1.
#[derive(Debug, Clone)]
struct Bluestein {
    n: usize,
    inner: Radix2,
    /// e^{−iπk²/N}, k < n.
    chirp: Vec<Complex>,
    /// The transform of the zero-padded conjugate chirp, divided by m (so the inverse needs no
    /// extra scaling).
    kernel: Vec<Complex>,
}

impl Bluestein {
    fn new(n: usize) -> Self {
        let m = (2 * n - 1).next_power_of_two();
        let inner = Radix2::new(m);
        // k² mod 2N keeps the angle small and exact for large k.
        let chirp: Vec<Complex> = (0..n as u64)
            .map(|k| {
                let k2 = (k * k) % (2 * n as u64);
                Complex::cis(-PI * k2 as f64 / n as f64)
            })
            .collect();
        let mut kernel = vec![Complex::default(); m];
        kernel[0] = chirp[0].conj();
        for k in 1..n {
            kernel[k] = chirp[k].conj();
            kernel[m - k] = chirp[k].conj();
        }
        inner.forward(&mut kernel);
        let scale = 1.0 / m as f64;
        for z in &mut kernel {
            *z *= scale;
        }
        Bluestein {
            n,
            inner,
            chirp,
            kernel,
        }
    }

    fn forward(&self, data: &mut [Complex], scratch: &mut Vec<Complex>) {
        let m = self.inner.n;
        scratch.clear();
        scratch.resize(m, Complex::default());
        for k in 0..self.n {
            scratch[k] = data[k] * self.chirp[k];
        }
        self.inner.forward(scratch);
        for (z, k) in scratch.iter_mut().zip(&self.kernel) {
            *z *= *k;
        }
        // Inverse transform as conj(FFT(conj(·))).
        for z in scratch.iter_mut() {
            *z = z.conj();
        }
        self.inner.forward(scratch);
        for k in 0..self.n {
            data[k] = scratch[k].conj() * self.chirp[k];
        }
    }
}

#[derive(Debug, Clone)]
enum Algorithm {
    Radix2(Radix2),
    Bluestein(Box<Bluestein>),
}

/// A forward DFT of one length, planned once and applied many times.
#[derive(Debug, Clone)]
pub struct Fft {
    algorithm: Algorithm,
    n: usize,
    scratch: Vec<Complex>,
}

impl Fft {
    /// Plans a transform of length `n ≥ 1`: radix-2 when `n` is a power of two, Bluestein
    /// otherwise. Memory: about 2n complex numbers (radix-2) or 4·2^⌈log₂(2n−1)⌉ (Bluestein).
    pub fn new(n: usize) -> Self {
        let n = n.max(1);
        let algorithm = if n.is_power_of_two() {
            Algorithm::Radix2(Radix2::new(n))
        } else {
            Algorithm::Bluestein(Box::new(Bluestein::new(n)))
        };
        Fft {
            algorithm,
            n,
            scratch: Vec::new(),
        }
    }

    /// The transform length.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Always false: a plan has length ≥ 1.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Transforms `data` in place. `data.len()` must equal [`Fft::len`]; a slice of another
    /// length is left unchanged (this is internal machinery: callers size their buffers from
    /// the plan).
    pub fn forward(&mut self, data: &mut [Complex]) {
        if data.len() != self.n {
            return;
        }
        match &self.algorithm {
            Algorithm::Radix2(p) => p.forward(data),
            Algorithm::Bluestein(p) => p.forward(data, &mut self.scratch),
        }
    }

    /// Transforms two real sequences of length N at once (as one complex sequence x + iy) and
    /// returns their one-sided spectra X_k, Y_k for k = 0 … N/2 (Hermitian symmetry:
    /// X_k = (Z_k + conj Z_{N−k})/2, Y_k = (Z_k − conj Z_{N−k})/(2i)).
    pub fn forward_real_pair(
        &mut self,
        x: &[f64],
        y: &[f64],
        buffer: &mut Vec<Complex>,
        out_x: &mut [Complex],
        out_y: &mut [Complex],
    ) {
        let n = self.n;
        buffer.clear();
        buffer.extend(
            x.iter()
                .zip(y)
                .take(n)
                .map(|(&re, &im)| Complex::new(re, im)),
        );
        buffer.resize(n, Complex::default());
        self.forward(buffer);
        let bins = (n / 2 + 1).min(out_x.len()).min(out_y.len());
        for k in 0..bins {
            let z = buffer[k];
            let zc = buffer[(n - k) % n].conj();
            out_x[k] = (z + zc) * 0.5;
            let d = z - zc;
            // d / (2i) = (d.im, −d.re)/2
            out_y[k] = Complex::new(d.im * 0.5, -d.re * 0.5);
        }
    }
}

/// The DFT of a real sequence, one-sided: X_k for k = 0 … ⌊N/2⌋ (numpy's `fft.rfft`).
pub fn rfft(x: &[f64]) -> Vec<Complex> {
    if x.is_empty() {
        return Vec::new();
    }
    let mut plan = Fft::new(x.len());
    let mut data: Vec<Complex> = x.iter().map(|&v| Complex::new(v, 0.0)).collect();
    plan.forward(&mut data);
    data.truncate(x.len() / 2 + 1);
    data
}

#[cfg(test)]
mod tests {
    use super::*;

    fn naive(x: &[Complex]) -> Vec<Complex> {
        let n = x.len();
        (0..n)
            .map(|k| {
                x.iter()
                    .enumerate()
                    .fold(Complex::default(), |acc, (j, &v)| {
                        let a = -2.0 * PI * ((k * j) % n) as f64 / n as f64;
                        acc + v * Complex::cis(a)
                    })
            })
            .collect()
    }

    #[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
    fn matches_the_definition_for_many_lengths() {
        for n in [1usize, 2, 3, 4, 5, 7, 8, 12, 16, 17, 100, 128, 255, 1000] {
            let x: Vec<Complex> = (0..n)
                .map(|i| Complex::new((i as f64 * 0.37).sin() + 0.1, (i as f64 * 1.3).cos()))
                .collect();
            let mut y = x.clone();
            Fft::new(n).forward(&mut y);
            let z = naive(&x);
            let scale = z.iter().map(|c| c.norm()).fold(1.0, f64::max);
            for (a, b) in y.iter().zip(&z) {
                assert!((*a - *b).norm() < 1e-11 * scale, "n = {n}: {a:?} vs {b:?}");
            }
        }
    }
}
