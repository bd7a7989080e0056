/**
 * The predicted speed step: the speed loop of `loop.ts` simulated period by period on the fitted rigid plant
 * J·dω/dt = T − B·ω (docs/what-if.md). Each period: the speed is measured as the position difference over the period,
 * filtered, the current demand computed (the integral used, then updated), filtered by the current-command filters,
 * and held as the torque Kt·i over the period; the mechanics are integrated exactly over that period (zero-order
 * hold). The current loop is taken as ideal: the fitted plant has no current-loop dynamics.
 */

import type { LoopParams } from "./loop";

export interface PlantFit {
  inertia_kgm2: number;
  viscous_friction_nms_per_rad: number;
}

export interface StepResponse {
  time_s: number[];
  /** measured (unfiltered) shaft speed per period, as a fraction of the step */
  speed: number[];
}

/** The mechanics over one period with a held torque: the new speed and the angle turned. */
function period(omega: number, torque: number, fit: PlantFit, dt: number): [number, number] {
  const j = fit.inertia_kgm2, b = fit.viscous_friction_nms_per_rad;
  if (b * dt < 1e-9 * j) {
    return [omega + (torque / j) * dt, omega * dt + (torque / j) * dt * dt / 2];
  }
  const beta = b / j, final = torque / b, decay = Math.exp(-beta * dt);
  return [final + (omega - final) * decay, final * dt + ((omega - final) * (1 - decay)) / beta];
}

interface Filters {
  speed: number;
  derivative: number;
  command: number[];
}

function alphas(params: LoopParams): Filters {
  const dt = params.periodS;
  const corner = (hz: number) => 1 - Math.exp(-2 * Math.PI * hz * dt);
  return {
    speed: params.speedFilterS > 0 ? 1 - Math.exp(-dt / params.speedFilterS) : 1,
    derivative: params.kdFilterHz > 0 ? corner(params.kdFilterHz) : 1,
    command: params.currentFiltersHz.filter((hz) => hz > 0).map(corner),
  };
}

/** The response to a unit speed step at t = 0, over `durationS`. */
export function stepResponse(params: LoopParams, fit: PlantFit, durationS: number): StepResponse {
  const dt = params.periodS;
  const a = alphas(params);
  const states = a.command.map(() => 0);
  const leak = 2 * Math.PI * params.kiLeakHz;
  let omega = 0, measured = 0, filtered = 0, previous = 0, derivative = 0, integral = 0;
  const time: number[] = [], speed: number[] = [];
  const steps = Math.max(1, Math.round(durationS / dt));
  for (let k = 0; k < steps; k++) {
    filtered += a.speed * (measured - filtered);
    const error = 1 - filtered;
    derivative += a.derivative * ((filtered - previous) / dt - derivative);
    previous = filtered;
    let demand = params.kp * error + params.ki * integral - params.kc * filtered - params.kd * derivative;
    integral += (error - leak * integral) * dt;
    for (let n = 0; n < states.length; n++) demand = states[n] += a.command[n] * (demand - states[n]);
    const [next, turned] = period(omega, params.kt * demand, fit, dt);
    omega = next;
    measured = turned / dt;
    time.push((k + 1) * dt);
    speed.push(measured);
  }
  return { time_s: time, speed };
}

/** −3 dB bandwidth of a step response: the Fourier transform of its derivative (the impulse response). */
export function stepBandwidth(step: StepResponse, dt: number): number | null {
  const impulse = step.speed.map((value, n) => (value - (n > 0 ? step.speed[n - 1] : 0)));
  const gain = (hz: number) => {
    let re = 0, im = 0;
    for (let n = 0; n < impulse.length; n++) {
      const angle = -2 * Math.PI * hz * n * dt;
      re += impulse[n] * Math.cos(angle);
      im += impulse[n] * Math.sin(angle);
    }
    return Math.hypot(re, im);
  };
  const level = gain(0) / Math.SQRT2;
  let low = 0;
  for (let hz = 1; hz < 0.5 / dt; hz *= 1.02) {
    if (gain(hz) < level) {
      for (let n = 0; n < 30; n++) {
        const mid = (low + hz) / 2;
        if (gain(mid) < level) hz = mid;
        else low = mid;
      }
      return hz;
    }
    low = hz;
  }
  return null;
}
