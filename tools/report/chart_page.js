// Page helpers shared by the report's charts (report_charts.js) and the
// comparison's (compare_charts.js): each page embeds this script before its own.
window.RmsCharts = (function () {
  'use strict';

  // A new element with the given properties, appended to parent.
  function el(tag, props, parent) {
    const e = Object.assign(document.createElement(tag), props);
    parent.appendChild(e);
    return e;
  }

  // A titled section in #rms-charts holding a canvas (fixed height, or fixed
  // aspect ratio when height is null).
  function section(title, height) {
    const div = el('div', { className: 'rms-chart' }, document.getElementById('rms-charts'));
    el('h3', { textContent: title }, div);
    const box = el('div', {}, div);
    box.style.cssText = 'position:relative' + (height ? ';height:' + height + 'px' : '');
    return { div, box, canvas: el('canvas', {}, box) };
  }

  return { el, section };
})();
