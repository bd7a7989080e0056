/**
 * The editor's sequences as SEQUENCE.TXT and back: the editor keeps the server's JSON form (`SequenceModel`: values in
 * the file's spellings) and sends the text it writes here to the server's file reader, the one validation
 * (docs/sequences.md). `lineMap` tells which sequence and keyword each line of that text holds, so the reader's
 * issues (file, line, keyword) land on the field they concern.
 */

import type { Keyword, KeywordCatalog, SequenceRow } from "../../client/sequences";

export type Value = string | number | null;
export const PATTERN_WIDTH = 8;
export const EMPTY_PATTERN = "........";
/** Keywords every type has: kept when a sequence changes its type. */
export const COMMON = ["Tempo", "Trigger", "Output", "StartCond", "EndCond", "SeqNext", "SeqCount", "SeqLink"];

export interface Located {
  sequence: number;
  keyword: string | null;
}

/** SEQUENCE.TXT of the rows, by ascending number; a null (a default the file cannot spell) or empty value is left out. */
export function toText(rows: SequenceRow[]): { text: string; lines: Map<number, Located> } {
  const out: string[] = [];
  const lines = new Map<number, Located>();
  const add = (line: string, located: Located) => {
    out.push(line);
    lines.set(out.length, located);
  };
  for (const row of [...rows].sort((a, b) => a.sequence - b.sequence)) {
    add(`SeqNb=${row.sequence}`, { sequence: row.sequence, keyword: "SeqNb" });
    add(`SeqType=${row.type}`, { sequence: row.sequence, keyword: "SeqType" });
    for (const [keyword, value] of Object.entries(row.values)) {
      const spelled = spell(value ?? null, isPattern(keyword));
      if (spelled !== null) add(`${keyword}=${spelled}`, { sequence: row.sequence, keyword });
    }
  }
  return { text: out.map((line) => `${line}\n`).join(""), lines };
}

function spell(value: Value, pattern: boolean): string | null {
  if (value === null || value === "") return null;
  return pattern ? `"${String(value)}"` : String(value);
}

export function isPattern(keyword: string): boolean {
  return keyword === "Output" || keyword === "StartCond" || keyword === "EndCond";
}

/** A new sequence of `type` at `number`: the catalogue's defaults, with the common values of `previous` kept. */
export function newSequence(catalog: KeywordCatalog, type: string, number: number, previous?: SequenceRow): SequenceRow {
  const values: Record<string, Value> = {};
  for (const keyword of catalog.keywords[type] ?? []) {
    const kept = previous && (COMMON.includes(keyword.name) || keyword.name in previous.values);
    values[keyword.name] = kept ? (previous.values[keyword.name] ?? null) : (keyword.default ?? null);
  }
  return { sequence: number, type, values };
}

/** The rows after importing `file` rows: LOAD replaces them all, MERGE replaces the numbers the file declares. */
export function merged(current: SequenceRow[], file: SequenceRow[], mode: "load" | "merge"): SequenceRow[] {
  if (mode === "load") return file;
  const declared = new Set(file.map((row) => row.sequence));
  return [...current.filter((row) => !declared.has(row.sequence)), ...file].sort((a, b) => a.sequence - b.sequence);
}

/** The range a number keyword allows, as the editor shows it ("1..65535"). */
export function allowedText(keyword: Keyword): string {
  return (keyword.allowed ?? []).map(([low, high]) => (low === high ? `${low}` : `${low}..${high}`)).join(", ");
}

/** A pattern with bit `bit` (0 = rightmost character) stepped . → 1 → 0 → . */
export function stepBit(pattern: string, bit: number): string {
  const chars = (pattern || EMPTY_PATTERN).padStart(PATTERN_WIDTH, ".").split("");
  const at = PATTERN_WIDTH - 1 - bit;
  chars[at] = chars[at] === "." ? "1" : chars[at] === "1" ? "0" : ".";
  return chars.join("");
}

/** One line saying what a sequence does (the table's summary column). */
export function summary(row: SequenceRow): string {
  const v = row.values;
  const next = v.SeqNext === -1 || v.SeqNext == null ? "end" : `→ ${v.SeqNext}`;
  const count = v.SeqCount ? `, ${v.SeqCount}× → ${v.SeqLink}` : "";
  const main = row.type === "POS" ? `${v.PosType ?? "ABS"} ${v.Pos ?? 0} @ ${v.Speed ?? 0}`
    : row.type === "SPEED" ? `${v.Speed ?? 0} for ${v.RunTime ?? 0} ms`
      : row.type === "HOME" ? `method ${v.Method ?? "?"}`
        : row.type === "TORQUE" ? `${v.Torque ?? 0} ‰ @ ${v.Speed ?? 0}` : `ratio config ${v.Config ?? 0}`;
  return `${main}; ${next}${count}`;
}
