/** The editor's rows: which entries a filter shows, and how they are grouped as in the manual. */

import { isVar, type Dictionary, type Entry, type OdObject } from "../../lib/od";
import { search, type Searchable } from "../../lib/search";

export type Row =
  | { kind: "group"; name: string; count: number }
  | { kind: "object"; object: OdObject }
  | { kind: "entry"; entry: Entry; sub: boolean };

export const ALL_GROUPS = "";
export const APPLICATION_GROUPS = "@application";

export interface Filter {
  text: string;
  group: string;
  /** The application template's groups (for `APPLICATION_GROUPS`). */
  applicationGroups: Set<string>;
  /** Only these entries (Only differences), or all. */
  only: ((entry: Entry) => boolean) | null;
}

export function entryGroup(entry: Entry): string {
  return entry.variable.group || entry.object.group;
}

export function filterEntries(index: Searchable[], filter: Filter): Entry[] {
  let found = search(index, filter.text);
  if (filter.group === APPLICATION_GROUPS) found = found.filter((entry) => filter.applicationGroups.has(entryGroup(entry)));
  else if (filter.group !== ALL_GROUPS) found = found.filter((entry) => entryGroup(entry) === filter.group);
  if (filter.only) found = found.filter(filter.only);
  return found;
}

/** A search shows its hits ranked, one row each; otherwise rows are grouped (see `groupRows`). */
export function rowsOf(dictionary: Dictionary, found: Entry[], searching: boolean): Row[] {
  return searching ? found.map((entry): Row => ({ kind: "entry", entry, sub: false })) : groupRows(dictionary, found);
}

/** Rows grouped as in the manual: group header, then objects in index order, ARRAY/RECORD with their subs. */
export function groupRows(dictionary: Dictionary, found: Entry[]): Row[] {
  const byGroup = new Map<string, Entry[]>();
  for (const entry of found) {
    const group = entryGroup(entry);
    if (!byGroup.has(group)) byGroup.set(group, []);
    byGroup.get(group)!.push(entry);
  }
  const order = [...dictionary.groups, ...[...byGroup.keys()].filter((group) => !dictionary.groups.includes(group))];
  const rows: Row[] = [];
  for (const group of order) {
    const list = byGroup.get(group);
    if (!list) continue;
    rows.push({ kind: "group", name: group, count: list.length });
    let lastObject: OdObject | null = null;
    for (const entry of list) {
      const compound = !isVar(entry.object);
      if (compound && entry.object !== lastObject) rows.push({ kind: "object", object: entry.object });
      lastObject = entry.object;
      rows.push({ kind: "entry", entry, sub: compound });
    }
  }
  return rows;
}
