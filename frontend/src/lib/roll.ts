/**
 * Live roll mode in the browser (docs/scope.md §8): the samples a roll's socket delivers, kept by sequence number
 * for the last few seconds, the gaps the roll (or a jump in the numbers) reported, and the decimation that turns
 * them into what the plot draws. Decimation is for display only: each pixel column shows the minimum and the
 * maximum of its samples (a spike of one sample stays visible), and a gap is a break in the line (a NaN point),
 * never a line across the missing numbers.
 */

export interface RollGap {
  from: number;
  /** First sequence number after the gap (exclusive end). */
  to: number;
  reason: string;
}

/** A `samples` event of the roll's socket. */
export interface RollSamples {
  type: "samples";
  seq: number;
  count: number;
  values: (number | null)[][];
  synced_at: [number, number];
}

export interface Series {
  x: number[];
  y: number[];
}

const UNEXPLAINED = "samples not received";

/** The samples of the last `keep` sequence numbers and every gap, from the socket's events. */
export class RollBuffer {
  readonly seqs: number[] = [];
  readonly values: number[][];
  readonly gaps: RollGap[] = [];
  received = 0;
  private next = 0;
  private reason: string | null = null;

  constructor(readonly channels: number, readonly keep: number) {
    this.values = Array.from({ length: channels }, () => []);
  }

  /** A `samples` event: numbers the roll skipped without saying so are a gap too. */
  add(event: RollSamples): void {
    if (event.seq > this.next) this.gaps.push({ from: this.next, to: event.seq, reason: this.reason ?? UNEXPLAINED });
    this.reason = null;
    for (let k = 0; k < event.count; k++) this.seqs.push(event.seq + k);
    event.values.forEach((column, n) => {
      for (const value of column) this.values[n].push(value === null ? NaN : value);
    });
    this.received += event.count;
    this.next = event.seq + event.count;
    this.trim();
  }

  /** A `gap` event: with its numbers it is a gap; without (this client fell behind) the next samples show them. */
  gap(event: { from?: number; to?: number; reason?: string }): void {
    const reason = event.reason ?? UNEXPLAINED;
    if (event.from === undefined || event.to === undefined) {
      this.reason = reason;
      return;
    }
    if (event.to > event.from) this.gaps.push({ from: event.from, to: event.to, reason });
    this.next = Math.max(this.next, event.to);
  }

  get lost(): number {
    return this.gaps.reduce((sum, gap) => sum + gap.to - gap.from, 0);
  }

  get last(): number {
    return this.seqs.length ? this.seqs[this.seqs.length - 1] : -1;
  }

  private trim(): void {
    const excess = this.seqs.length - this.keep;
    if (excess < this.keep / 4) return; // trimmed in chunks: a splice per batch would copy the buffer each time
    this.seqs.splice(0, excess);
    for (const column of this.values) column.splice(0, excess);
  }
}

/**
 * The samples of sequence numbers in [`from`, `to`) (times `seq × period`) as at most 2 points per pixel column:
 * its minimum and maximum in the order they occur. A jump in the numbers is a NaN point (a break).
 */
export function decimate(seqs: number[], values: number[], period: number, from: number, to: number, columns: number): Series {
  const out: Series = { x: [], y: [] };
  const width = Math.max((to - from) / Math.max(columns, 1), 1);
  let column = -1, low = -1, high = -1, previous: number | null = null;
  const flush = () => {
    if (low < 0) return;
    for (const i of low === high ? [low] : low < high ? [low, high] : [high, low]) push(out, seqs[i] * period, values[i]);
    low = high = -1;
  };
  for (let i = lowerBound(seqs, from); i < seqs.length && seqs[i] < to; i++) {
    if (previous !== null && seqs[i] !== previous + 1) {
      flush();
      push(out, (previous + 1) * period, NaN);
    }
    previous = seqs[i];
    const here = Math.floor((seqs[i] - from) / width);
    if (here !== column) {
      flush();
      column = here;
    }
    if (low < 0 || values[i] < values[low]) low = i;
    if (high < 0 || values[i] > values[high]) high = i;
  }
  flush();
  return out;
}

function push(series: Series, x: number, y: number): void {
  series.x.push(x);
  series.y.push(y);
}

/** The first index whose number is ≥ `seq` (the numbers are increasing). */
function lowerBound(seqs: number[], seq: number): number {
  let low = 0, high = seqs.length;
  while (low < high) {
    const middle = (low + high) >> 1;
    if (seqs[middle] < seq) low = middle + 1;
    else high = middle;
  }
  return low;
}
