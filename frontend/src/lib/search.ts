/**
 * Search over the dictionary's sub-objects: by address (`60F9`, `0x60F9.2`, `60f9sub2`, `60F9,2`), by name or
 * by description words ("KPv" finds 0x60F9 sub 2, whose description starts with "KPv"). Texts are lower-cased once
 * when the index is built, so filtering 1,000 objects is a plain scan of short strings.
 */

import type { Entry } from "./od";

export interface Searchable {
  entry: Entry;
  index: number;
  subindex: number;
  hex: string;
  name: string;
  words: string;
}

export function buildIndex(list: readonly Entry[]): Searchable[] {
  return list.map((entry) => {
    const { object, variable } = entry;
    const name = variable.name.toLowerCase();
    const parent = object.name.toLowerCase();
    const enumText = Object.values(variable.enum).join(" ");
    const bitText = variable.bits.map((bit) => bit.name).join(" ");
    return {
      entry,
      index: object.index,
      subindex: variable.subindex,
      hex: object.index.toString(16).padStart(4, "0"),
      name,
      words: [name, parent === name ? "" : parent, variable.description, variable.unit, enumText, bitText]
        .join(" ")
        .toLowerCase(),
    };
  });
}

export type Query =
  | { kind: "all" }
  | { kind: "address"; index: number; subindex: number | null }
  | { kind: "text"; tokens: string[] };

const ADDRESS = /^(?:0x)?([0-9a-f]{4})(?:\s*(?:[.,:/ ]|sub|s)\s*(?:0x([0-9a-f]+)|(\d+)))?h?$/i;

export function parseQuery(text: string): Query {
  const trimmed = text.trim().toLowerCase();
  if (trimmed === "") return { kind: "all" };
  const match = ADDRESS.exec(trimmed);
  // "60f9" or "0x60f9" is an address; a word of hex letters only ("feed", "face") is searched as text.
  if (match && (/\d/.test(match[1]) || trimmed.startsWith("0x"))) {
    const subindex = match[2] !== undefined ? parseInt(match[2], 16) : match[3] !== undefined ? Number(match[3]) : null;
    return { kind: "address", index: parseInt(match[1], 16), subindex };
  }
  return { kind: "text", tokens: trimmed.split(/\s+/) };
}

/**
 * Entries matching `text`, best first: exact name, name prefix, name contains, then description matches;
 * ties keep dictionary order. An address query returns that object (or that one sub) in order.
 */
export function search(index: readonly Searchable[], text: string): Entry[] {
  const query = parseQuery(text);
  if (query.kind === "all") return index.map((item) => item.entry);
  if (query.kind === "address") {
    return index
      .filter((item) => item.index === query.index && (query.subindex === null || item.subindex === query.subindex))
      .map((item) => item.entry);
  }
  const scored: { item: Searchable; score: number; order: number }[] = [];
  index.forEach((item, order) => {
    let score = 0;
    for (const token of query.tokens) {
      const tokenScore = scoreToken(item, token);
      if (tokenScore === 0) return;
      score += tokenScore;
    }
    scored.push({ item, score, order });
  });
  scored.sort((a, b) => b.score - a.score || a.order - b.order);
  return scored.map(({ item }) => item.entry);
}

function scoreToken(item: Searchable, token: string): number {
  if (item.name === token) return 100;
  if (item.name.startsWith(token)) return 60;
  if (wordStarts(item.name, token)) return 50;
  if (item.hex.startsWith(token.replace(/^0x/, "")) && /^(0x)?[0-9a-f]{2,4}$/.test(token)) return 45;
  if (wordStarts(item.words, token)) return 30;
  if (item.name.includes(token)) return 20;
  if (item.words.includes(token)) return 10;
  return 0;
}

function wordStarts(text: string, token: string): boolean {
  let position = text.indexOf(token);
  while (position !== -1) {
    if (position === 0 || !/[a-z0-9]/.test(text[position - 1])) return true;
    position = text.indexOf(token, position + 1);
  }
  return false;
}
