/** Complex numbers for frequency responses: small immutable pairs, only the operations the loop model needs. */

export interface Complex {
  re: number;
  im: number;
}

export const complex = (re: number, im = 0): Complex => ({ re, im });
export const add = (a: Complex, b: Complex): Complex => ({ re: a.re + b.re, im: a.im + b.im });
export const mul = (a: Complex, b: Complex): Complex => ({ re: a.re * b.re - a.im * b.im, im: a.re * b.im + a.im * b.re });
export const scale = (a: Complex, k: number): Complex => ({ re: a.re * k, im: a.im * k });

export function div(a: Complex, b: Complex): Complex {
  const d = b.re * b.re + b.im * b.im;
  return { re: (a.re * b.re + a.im * b.im) / d, im: (a.im * b.re - a.re * b.im) / d };
}

export const abs = (a: Complex): number => Math.hypot(a.re, a.im);
export const arg = (a: Complex): number => Math.atan2(a.im, a.re);

/** e^{jθ} */
export const unit = (theta: number): Complex => ({ re: Math.cos(theta), im: Math.sin(theta) });

/** From a Bode point: magnitude in dB, phase in degrees. */
export function fromBode(magnitudeDb: number, phaseDeg: number): Complex {
  const magnitude = 10 ** (magnitudeDb / 20);
  const phase = (phaseDeg * Math.PI) / 180;
  return { re: magnitude * Math.cos(phase), im: magnitude * Math.sin(phase) };
}

export const db = (a: Complex): number => 20 * Math.log10(abs(a));

/** Phases in degrees, unwrapped along the frequency axis (no 360° jumps between neighbours). */
export function unwrapDeg(values: Complex[]): number[] {
  const out: number[] = [];
  let offset = 0;
  let previous: number | null = null;
  for (const value of values) {
    const raw = (arg(value) * 180) / Math.PI;
    if (previous !== null) {
      while (raw + offset - previous > 180) offset -= 360;
      while (raw + offset - previous < -180) offset += 360;
    }
    previous = raw + offset;
    out.push(previous);
  }
  return out;
}
