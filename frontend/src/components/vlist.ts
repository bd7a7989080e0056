/**
 * A virtualised list of fixed-height rows: only the rows in view (plus a margin) exist in the DOM, so a dictionary
 * of thousands of entries scrolls and filters without lag.
 */

import { h } from "../lib/dom";

const OVERSCAN = 8;

export class VirtualList<T> {
  readonly element: HTMLElement;
  private readonly spacer: HTMLElement;
  private readonly rows: HTMLElement;
  private items: T[] = [];
  private frame = 0;
  private first = -1;
  private last = -1;
  /** Called after rows were (re)rendered, with the items now in view (lazy reading of drive values). */
  onVisible: ((items: T[]) => void) | null = null;

  constructor(
    private readonly rowHeight: number,
    private readonly renderRow: (item: T, position: number) => HTMLElement,
  ) {
    this.rows = h("div", { class: "rows" });
    this.spacer = h("div", { class: "spacer" }, this.rows);
    this.element = h("div", { class: "pscroll", tabindex: "0" }, this.spacer);
    this.element.addEventListener("scroll", () => this.schedule());
    new ResizeObserver(() => this.schedule()).observe(this.element);
  }

  setItems(items: T[]): void {
    this.items = items;
    this.spacer.style.height = `${items.length * this.rowHeight}px`;
    this.first = this.last = -1;
    this.render();
  }

  /** Re-render the rows in view (values changed, selection moved). */
  refresh(): void {
    this.first = this.last = -1;
    this.schedule();
  }

  count(): number {
    return this.items.length;
  }

  itemAt(position: number): T | undefined {
    return this.items[position];
  }

  scrollToPosition(position: number): void {
    const top = position * this.rowHeight;
    const bottom = top + this.rowHeight;
    const view = this.element;
    if (top < view.scrollTop) view.scrollTop = top;
    else if (bottom > view.scrollTop + view.clientHeight) view.scrollTop = bottom - view.clientHeight;
    this.schedule();
  }

  private schedule(): void {
    if (this.frame) return;
    this.frame = requestAnimationFrame(() => {
      this.frame = 0;
      this.render();
    });
  }

  private render(): void {
    const height = this.element.clientHeight || 600;
    const first = Math.max(0, Math.floor(this.element.scrollTop / this.rowHeight) - OVERSCAN);
    const last = Math.min(this.items.length, Math.ceil((this.element.scrollTop + height) / this.rowHeight) + OVERSCAN);
    if (first === this.first && last === this.last) return;
    this.first = first;
    this.last = last;
    this.rows.style.transform = `translateY(${first * this.rowHeight}px)`;
    const fragment = document.createDocumentFragment();
    for (let position = first; position < last; position++) fragment.append(this.renderRow(this.items[position], position));
    this.rows.replaceChildren(fragment);
    this.onVisible?.(this.items.slice(first, last));
  }
}
