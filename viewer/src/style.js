// style.js - the page's style sheet, injected by main.js (the page has no other file).
export const STYLE = `
html, body { margin: 0; height: 100%; background: #111; color: #ddd; font: 13px/1.4 system-ui, sans-serif; }
#view { position: absolute; left: 0; top: 0; bottom: 0; right: 300px; }
#view canvas { display: block; }
#panel { position: absolute; right: 0; top: 0; bottom: 0; width: 300px; box-sizing: border-box;
  padding: 10px 12px; overflow-y: auto; background: #1c1c1c; border-left: 1px solid #333; }
#panel h1 { font-size: 16px; margin: 0 0 4px; }
.source, .stats, .help { color: #999; word-break: break-all; margin-bottom: 6px; }
.summary { color: #999; margin-bottom: 6px; }
.row { display: flex; align-items: center; gap: 6px; margin: 6px 0; }
.row label { width: 92px; color: #aaa; }
.row select, .row input[type=range] { flex: 1; min-width: 0; }
[hidden] { display: none !important; }
#legend { margin: 10px 0; }
#legend-title { margin-bottom: 4px; }
.legend-body { display: flex; gap: 8px; height: 200px; }
#legend-ticks { display: flex; flex-direction: column; justify-content: space-between; }
#picked { margin: 10px 0; padding: 6px; background: #262626; min-height: 40px; }
.field .label { color: #aaa; margin-right: 6px; }
#error { position: absolute; left: 20px; top: 20px; right: 320px; padding: 10px; background: #600; color: #fff; }
`;
