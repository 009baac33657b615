// uPlot, loaded from web/vendor/ (filled by `npm ci` in web/, see web/scripts/vendor.mjs).
// Loaded on demand so the fleet view works even where the charts library is missing.

let loading = null;

export function loadUPlot() {
  if (!loading) {
    const css = document.createElement('link');
    css.rel = 'stylesheet';
    css.href = '/vendor/uPlot.min.css';
    document.head.append(css);
    loading = import('/vendor/uPlot.esm.js').then((m) => m.default);
  }
  return loading;
}

export const COLORS = ['#0047ab', '#c00018', '#0a6d2c', '#7a3cb8', '#b35c00'];

// Width of a chart's container, for uPlot (which sizes in pixels).
export function widthOf(node) {
  const cs = getComputedStyle(node);
  const inner = node.clientWidth - parseFloat(cs.paddingLeft) - parseFloat(cs.paddingRight);
  return Math.max(260, Math.floor(inner || 320));
}

// Resizes every chart to its container when the window changes size.
export function autoResize(charts, node, height) {
  const ro = new ResizeObserver(() => {
    for (const c of charts()) c.setSize({ width: widthOf(node), height });
  });
  ro.observe(node);
  return () => ro.disconnect();
}

// Vertical markers (alarm events) drawn on a chart: [{x, color, label}].
export function markersPlugin(getMarkers) {
  return {
    hooks: {
      draw: [
        (u) => {
          const { ctx } = u;
          const { top, height } = u.bbox;
          ctx.save();
          for (const m of getMarkers()) {
            const x = Math.round(u.valToPos(m.x, 'x', true));
            if (x < u.bbox.left || x > u.bbox.left + u.bbox.width) continue;
            ctx.strokeStyle = m.color;
            ctx.lineWidth = 3 * devicePixelRatio;
            ctx.beginPath();
            ctx.moveTo(x, top);
            ctx.lineTo(x, top + height);
            ctx.stroke();
          }
          ctx.restore();
        },
      ],
    },
  };
}
