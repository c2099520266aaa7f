// Live tactile heat maps: one panel per pad (heat map + intensity sum over simulation time), fed by the
// /view/<scene>/tactile event stream. Intensities are 12-bit (0..4095), row-major, rows along the pad's y.
const kHistorySeconds = 20;
const kScale = 14;  // screen pixels per texel

// Black → red → yellow → white, the usual tactile heat map.
function heat(value) {
  const t = Math.min(1, Math.max(0, value / 4095));
  return [Math.min(255, 3 * 255 * t), Math.min(255, Math.max(0, 3 * 255 * t - 255)), Math.max(0, 3 * 255 * t - 510)];
}

export class TactilePanels {
  constructor(container, arrays) {
    this.pads = new Map();
    for (const array of arrays) {
      const box = document.createElement('div');
      box.className = 'pad';
      box.innerHTML = `<div>${array.id} <span class="sum"></span></div>`;
      const image = document.createElement('canvas');
      image.width = array.cols;
      image.height = array.rows;
      image.style.width = `${array.cols * kScale}px`;
      image.style.height = `${array.rows * kScale}px`;
      image.dataset.sensor = array.id;
      const chart = document.createElement('canvas');
      chart.width = 260;
      chart.height = 60;
      box.append(image, chart);
      container.append(box);
      this.pads.set(array.id, { array, image, chart, sum: box.querySelector('.sum'), history: [], frames: 0, maxIntensity: 0,
                                peakIntensity: 0, peakTime: null, peakRed: 0 });
    }
  }

  // The canvas a pad's 3D plane shows (same pixels as the panel).
  canvasFor(id) { return this.pads.get(id)?.image; }

  update(reading) {
    const pad = this.pads.get(reading.sensor_id);
    if (!pad) return null;
    const context = pad.image.getContext('2d');
    const pixels = context.createImageData(reading.cols, reading.rows);
    let max = 0;
    reading.intensities.forEach((value, i) => {
      const [r, g, b] = heat(value);
      pixels.data.set([r, g, b, 255], 4 * i);
      max = Math.max(max, value);
    });
    context.putImageData(pixels, 0, 0);
    pad.frames += 1;
    pad.maxIntensity = max;
    if (max > pad.peakIntensity) {  // the strongest touch so far, and what the panel drew for it
      pad.peakIntensity = max;
      pad.peakTime = reading.time;
      const drawn = context.getImageData(0, 0, reading.cols, reading.rows).data;
      pad.peakRed = drawn.reduce((m, v, i) => (i % 4 === 0 ? Math.max(m, v) : m), 0);
    }
    pad.sum.textContent = `Σ = ${reading.intensity_sum}`;
    pad.history.push([reading.time, reading.intensity_sum]);
    while (pad.history.length && pad.history[0][0] < reading.time - kHistorySeconds) pad.history.shift();
    if (pad.history.length && pad.history[pad.history.length - 1][0] < pad.history[0][0]) pad.history = [[reading.time, reading.intensity_sum]];
    this.drawHistory(pad);
    return pad;
  }

  drawHistory(pad) {
    const { chart, history } = pad;
    const context = chart.getContext('2d');
    context.fillStyle = '#111';
    context.fillRect(0, 0, chart.width, chart.height);
    if (history.length < 2) return;
    const t0 = history[0][0], t1 = history[history.length - 1][0];
    const top = Math.max(1, ...history.map(([, sum]) => sum));
    context.strokeStyle = '#ff9b3d';
    context.beginPath();
    history.forEach(([t, sum], i) => {
      const x = ((t - t0) / Math.max(1e-9, t1 - t0)) * (chart.width - 1);
      const y = chart.height - 2 - (sum / top) * (chart.height - 4);
      if (i === 0) context.moveTo(x, y);
      else context.lineTo(x, y);
    });
    context.stroke();
    context.fillStyle = '#aaa';
    context.fillText(`Σ max ${top} over ${(t1 - t0).toFixed(2)} s`, 4, 11);
  }

  stats() {
    return Object.fromEntries([...this.pads].map(([id, pad]) => [id, {
      frames: pad.frames, maxIntensity: pad.maxIntensity, peakIntensity: pad.peakIntensity, peakTime: pad.peakTime, peakRed: pad.peakRed,
    }]));
  }
}
