/**
 * Values the drive changes by itself — read-only measurements and states, procedure status, set-points: not saved
 * in a drive file — follow the drive while they are shown: the rows in view and the selected entry are watched
 * through the server's terminal socket (the server samples them, one watch for the whole editor, no timer per row)
 * and every sample is stored in the editor's cells, which the rows and the detail pane bind to.
 */

import type { DriveCell, ParameterStore } from "./store";
import { isReadable, type Entry } from "../../lib/od";

/** The terminal watches at most 32 objects (`services/terminal.py`). */
export const MAX_LIVE = 32;
export const LIVE_PERIOD_MS = 500;

/** Watch these entries (an empty list stops the watch); samples arrive through `onCells`. */
export type Watcher = (entries: Entry[], onCells: (cells: Map<string, DriveCell>) => void) => void;

/** An entry whose drive value may change without anyone writing it. */
export function isLive(entry: Entry): boolean {
  const access = entry.variable.access.toLowerCase();
  return isReadable(access) && access !== "const" && entry.variable.save_type === "NONE";
}

export class LiveValues {
  private key = "";

  constructor(
    private readonly store: ParameterStore,
    private readonly watcher: Watcher | null,
  ) {}

  /** Watch the live entries among those shown (the selected one first), while the drive is online. */
  show(shown: Entry[], selected: Entry | null): void {
    if (!this.watcher) return;
    const wanted = this.store.online.rawVal ? [...new Set([selected, ...shown])].filter((entry): entry is Entry => entry !== null && isLive(entry)).slice(0, MAX_LIVE) : [];
    const key = wanted.map((entry) => entry.key).join(" ");
    if (key === this.key) return;
    this.key = key;
    this.watcher(wanted, (cells) => {
      for (const [entryKey, cell] of cells) {
        const slot = this.store.driveCell(entryKey);
        const previous = slot.rawVal;
        if (!previous || previous.raw !== cell.raw || previous.error !== cell.error) slot.val = cell;
      }
    });
  }

  stop(): void {
    if (this.key && this.watcher) this.watcher([], () => undefined);
    this.key = "";
  }
}
