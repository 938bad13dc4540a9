// The window of x in view, shared by a recording's charts: zoom about a point, pan, and kept
// within the recording's extent.

/**
 * A view over x from `min` to `max`.
 */
export class View {
  /**
   * @param {number} min
   * @param {number} max
   */
  constructor(min, max) {
    this.min = min;
    this.max = max > min ? max : min + 1;
    this.x0 = this.min;
    this.x1 = this.max;
  }

  /**
   * Zooms by `factor` (< 1 in, > 1 out) about `x`.
   * @param {number} x
   * @param {number} factor
   */
  zoom(x, factor) {
    const span = Math.min(this.max - this.min, Math.max((this.x1 - this.x0) * factor, 1e-6));
    const at = (x - this.x0) / (this.x1 - this.x0);
    this.set(x - at * span, x - at * span + span);
  }

  /**
   * Moves the window by `dx`.
   * @param {number} dx
   */
  pan(dx) {
    this.set(this.x0 + dx, this.x1 + dx);
  }

  /** The whole recording. */
  reset() {
    this.set(this.min, this.max);
  }

  /**
   * Sets the window, moved inside the extent.
   * @param {number} x0
   * @param {number} x1
   */
  set(x0, x1) {
    const span = Math.min(x1 - x0, this.max - this.min);
    let a = x0;
    if (a < this.min) a = this.min;
    if (a + span > this.max) a = this.max - span;
    this.x0 = a;
    this.x1 = a + span;
  }
}
