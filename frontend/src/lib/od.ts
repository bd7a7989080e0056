/** The object dictionary as the server sends it (`GET /api/dictionaries/{device}`), plus helpers over it. */

import type { Schemas } from "../client/schema-types";
import { formatHex } from "./numbers";

export type Scalar = number | string | null;

// The dictionary's payloads are the server's pydantic models (generated into schema.d.ts by `make api-types`).
export type OdVariable = Schemas["EntryModel"];
export type OdObject = Schemas["ObjectModel"];
export type Dictionary = Schemas["DictionaryModel"];
export type DictionarySummary = Schemas["DictionarySummary"];

/** One (index, sub) together with its object: the unit the parameter editor lists, edits and searches. */
export interface Entry {
  key: string;
  object: OdObject;
  variable: OdVariable;
}

export function entryKey(index: number, subindex: number): string {
  return `${index}.${subindex}`;
}

export function isVar(object: OdObject): boolean {
  return object.kind.toUpperCase() === "VAR" || object.kind.toUpperCase() === "DOMAIN";
}

/** All sub-objects in dictionary order. */
export function entries(dictionary: Dictionary): Entry[] {
  const list: Entry[] = [];
  for (const object of dictionary.objects) {
    for (const variable of object.subs) list.push({ key: entryKey(object.index, variable.subindex), object, variable });
  }
  return list;
}

/** Address shown in the UI: `0x6041` for a VAR, `0x60F9.2` for a sub of an ARRAY/RECORD. */
export function address(entry: Entry): string {
  return isVar(entry.object) && entry.variable.subindex === 0
    ? formatHex(entry.object.index)
    : `${formatHex(entry.object.index)}.${entry.variable.subindex}`;
}

export type ValueKind = "integer" | "float" | "string" | "bytes";

/** How a data type (the server sends CiA 301 names: UNSIGNED16, REAL32, VISIBLE_STRING…) is shown and edited. */
export function valueKind(dataType: string): ValueKind {
  const name = dataType.toUpperCase();
  if (name === "BOOLEAN" || /^(INTEGER|UNSIGNED)\d+$/.test(name)) return "integer";
  if (name.startsWith("REAL")) return "float";
  if (name === "VISIBLE_STRING" || name === "UNICODE_STRING") return "string";
  return "bytes";
}

export function isWritable(access: string): boolean {
  return ["rw", "wo", "rwr", "rww"].includes(access.toLowerCase());
}

export function isReadable(access: string): boolean {
  return access.toLowerCase() !== "wo";
}

/** Short data type label for dense tables: U16, I32, R32, STR, DOM… */
export function shortType(dataType: string): string {
  const name = dataType.toUpperCase();
  const match = /^(UNSIGNED|INTEGER|REAL)(\d+)$/.exec(name);
  if (match) return `${match[1][0] === "U" ? "U" : match[1][0] === "I" ? "I" : "R"}${match[2]}`;
  return { BOOLEAN: "BOOL", VISIBLE_STRING: "STR", OCTET_STRING: "OCT", UNICODE_STRING: "USTR", DOMAIN: "DOM" }[name] ?? name;
}

/** Enumeration entries sorted by numeric value. */
export function enumOptions(variable: OdVariable): { value: number; text: string }[] {
  return Object.entries(variable.enum)
    .map(([value, text]) => ({ value: Number(value), text }))
    .sort((a, b) => a.value - b.value);
}

const TYPE_RANGES: Record<string, [number, number]> = {
  BOOLEAN: [0, 1],
  INTEGER8: [-128, 127],
  INTEGER16: [-32768, 32767],
  INTEGER24: [-(2 ** 23), 2 ** 23 - 1],
  INTEGER32: [-(2 ** 31), 2 ** 31 - 1],
  UNSIGNED8: [0, 255],
  UNSIGNED16: [0, 65535],
  UNSIGNED24: [0, 2 ** 24 - 1],
  UNSIGNED32: [0, 2 ** 32 - 1],
};

/** Allowed raw range: the dictionary's low/high, else the data type's range (null for floats and texts). */
export function rawRange(variable: OdVariable): [number, number] | null {
  const typeRange = TYPE_RANGES[variable.data_type.toUpperCase()] ?? null;
  const low = variable.low ?? typeRange?.[0];
  const high = variable.high ?? typeRange?.[1];
  return low === undefined || high === undefined ? null : [low, high];
}

/** Hex digits a word of this type shows (U16 → 4). */
export function hexWidth(dataType: string): number {
  const match = /(\d+)$/.exec(dataType);
  return match ? Math.max(2, Number(match[1]) / 4) : 8;
}

/**
 * The dictionary as one node sees it: a default (or a DCF's configured value) written as `$NODEID+offset` becomes
 * that node's number. The server keeps the expression, since a dictionary is shared by every node of its device.
 */
export function forNode(dictionary: Dictionary, node: number): Dictionary {
  const resolve = (variable: OdVariable): OdVariable => ({
    ...variable,
    default: variable.default_node_offset != null ? node + variable.default_node_offset : variable.default,
    configured: variable.configured_node_offset != null ? node + variable.configured_node_offset : variable.configured,
  });
  return { ...dictionary, objects: dictionary.objects.map((object) => ({ ...object, subs: object.subs.map(resolve) })) };
}
