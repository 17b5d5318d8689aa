// What the labelling and proofreading pages share: $ (an element by id) and api (a JSON GET, or POST of body).
"use strict";

const $ = (id) => document.getElementById(id);

async function api(path, body) {
  const opts = body === undefined ? {} : {
    method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body),
  };
  const r = await fetch(path, opts);
  const data = await r.json().catch(() => ({}));
  if (!r.ok) throw new Error(data.error || `${path}: HTTP ${r.status}`);
  return data;
}
