/**
 * Amplitude spectrum of a captured signal: Hann window, zero padding to a power of two, radix-2 FFT. Magnitudes are
 * corrected for the window's coherent gain, so a sine of amplitude A on a bin shows as A (and a constant as itself
 * at 0 Hz).
 */

export interface Spectrum {
  frequency: number[];
  magnitude: number[];
}

export function hann(length: number): number[] {
  if (length === 1) return [1];
  return Array.from({ length }, (_, i) => 0.5 - 0.5 * Math.cos((2 * Math.PI * i) / (length - 1)));
}

export function spectrum(values: readonly number[], dt: number): Spectrum {
  const window = hann(values.length);
  const gain = window.reduce((sum, w) => sum + w, 0);
  const size = nextPowerOfTwo(values.length);
  const re = new Float64Array(size), im = new Float64Array(size);
  values.forEach((value, i) => (re[i] = value * window[i]));
  fftInPlace(re, im);
  const bins = size / 2 + 1;
  const frequency: number[] = [], magnitude: number[] = [];
  for (let k = 0; k < bins; k++) {
    frequency.push(k / (size * dt));
    const edge = k === 0 || k === size / 2;
    magnitude.push((Math.hypot(re[k], im[k]) * (edge ? 1 : 2)) / gain);
  }
  return { frequency, magnitude };
}

export function nextPowerOfTwo(n: number): number {
  let size = 1;
  while (size < n) size *= 2;
  return size;
}

/** Iterative radix-2 Cooley–Tukey FFT; `re.length` must be a power of two. */
export function fftInPlace(re: Float64Array, im: Float64Array): void {
  const n = re.length;
  for (let i = 1, j = 0; i < n; i++) {
    let bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) {
      [re[i], re[j]] = [re[j], re[i]];
      [im[i], im[j]] = [im[j], im[i]];
    }
  }
  for (let length = 2; length <= n; length *= 2) {
    const angle = (-2 * Math.PI) / length;
    for (let start = 0; start < n; start += length) {
      for (let k = 0; k < length / 2; k++) {
        const wr = Math.cos(angle * k), wi = Math.sin(angle * k);
        const a = start + k, b = a + length / 2;
        const tr = re[b] * wr - im[b] * wi, ti = re[b] * wi + im[b] * wr;
        re[b] = re[a] - tr;
        im[b] = im[a] - ti;
        re[a] += tr;
        im[a] += ti;
      }
    }
  }
}
