// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors
//
// The base mesh picked by hand on the page (paper §5.1, Fig. 6): vertices are sample indices,
// triangles join three of them. Every change can be undone; the checks the server's
// base_mesh_from_samples() makes (a manifold, orientable triangle set) are made here too, live,
// so the page can say what is wrong before anything is sent. No three.js here.

/** The key of an undirected edge. */
function edgeKey(a, b) {
  return a < b ? `${a},${b}` : `${b},${a}`;
}

export class PickedBaseMesh {
  constructor() {
    this.vertices = [];   // sample indices, in order of picking
    this.triangles = [];  // [a, b, c] sample indices, oriented consistently (see orient())
    this.history = [];    // what undo() takes back: {type: 'vertex' | 'triangle', ...}
  }

  hasVertex(sample) {
    return this.vertices.includes(sample);
  }

  /** Adds a picked sample as a base vertex; false if it already is one. */
  addVertex(sample) {
    if (!Number.isInteger(sample) || sample < 0) throw new RangeError(`not a sample index: ${sample}`);
    if (this.hasVertex(sample)) return false;
    this.vertices.push(sample);
    this.history.push({ type: 'vertex', sample });
    return true;
  }

  /**
   * Joins three base vertices into a triangle, turned to agree with the triangles it shares an
   * edge with (or as given). Refused (an Error saying why) if it repeats a vertex, names a
   * sample that is not a base vertex, or repeats a triangle.
   */
  join(a, b, c) {
    for (const v of [a, b, c]) {
      if (!this.hasVertex(v)) throw new Error(`sample ${v} is not a base vertex: pick it first`);
    }
    if (a === b || b === c || a === c) throw new Error('a triangle needs three different vertices');
    const key = [a, b, c].sort((x, y) => x - y).join(',');
    if (this.triangles.some((t) => [...t].sort((x, y) => x - y).join(',') === key)) {
      throw new Error(`samples ${a}, ${b}, ${c} are already a triangle`);
    }
    this.triangles.push([a, b, c]);
    this.history.push({ type: 'triangle' });
    this.orient();
    return this.triangles[this.triangles.length - 1];
  }

  /** Takes back the last change; returns what it was (null if nothing to undo). */
  undo() {
    const last = this.history.pop();
    if (!last) return null;
    if (last.type === 'triangle') {
      this.triangles.pop();
      this.orient();
    } else {
      // A vertex is only picked after the triangles that use it are undone (history order).
      this.vertices.pop();
    }
    return last.type;
  }

  clear() {
    this.vertices = [];
    this.triangles = [];
    this.history = [];
  }

  /**
   * Orients the triangles consistently across every shared edge: each edge-connected component
   * keeps the orientation of its first triangle and the others are turned to agree (breadth
   * first). Returns false if some component cannot be oriented (or has an edge of more than two
   * triangles, where orientation means nothing).
   */
  orient() {
    const byEdge = new Map();
    this.triangles.forEach((t, f) => {
      for (let k = 0; k < 3; ++k) {
        const key = edgeKey(t[k], t[(k + 1) % 3]);
        if (!byEdge.has(key)) byEdge.set(key, []);
        byEdge.get(key).push(f);
      }
    });
    const visited = new Array(this.triangles.length).fill(false);
    let orientable = true;
    const hasDirected = (t, a, b) => (t[0] === a && t[1] === b) || (t[1] === a && t[2] === b) ||
      (t[2] === a && t[0] === b);
    for (let seed = 0; seed < this.triangles.length; ++seed) {
      if (visited[seed]) continue;
      visited[seed] = true;
      const queue = [seed];
      while (queue.length > 0) {
        const f = queue.shift();
        const t = this.triangles[f];
        for (let k = 0; k < 3; ++k) {
          const a = t[k];
          const b = t[(k + 1) % 3];
          for (const g of byEdge.get(edgeKey(a, b))) {
            if (g === f) continue;
            const u = this.triangles[g];
            if (!visited[g]) {
              // A neighbour agrees when it runs the shared edge the other way, b to a.
              if (hasDirected(u, a, b)) this.triangles[g] = [u[0], u[2], u[1]];
              visited[g] = true;
              queue.push(g);
            } else if (hasDirected(this.triangles[g], a, b)) {
              orientable = false;
            }
          }
        }
      }
    }
    return orientable;
  }

  /**
   * The checks the server makes, with the figures of the picked mesh: counts, boundary edges,
   * components, Euler characteristic, and the problems (an empty list: it can be sent).
   */
  check() {
    const problems = [];
    const byEdge = new Map();
    for (const t of this.triangles) {
      for (let k = 0; k < 3; ++k) {
        const key = edgeKey(t[k], t[(k + 1) % 3]);
        byEdge.set(key, (byEdge.get(key) || 0) + 1);
      }
    }
    let boundaryEdges = 0;
    const badEdges = [];
    for (const [key, count] of byEdge) {
      if (count === 1) ++boundaryEdges;
      if (count > 2) {
        badEdges.push(key.split(',').map(Number));
        problems.push(`not a manifold: the edge between samples ${key.replace(',', ' and ')} has ${count} triangles`);
      }
    }
    // Around each vertex its triangles must form one fan (joined through shared edges).
    const badVertices = [];
    const used = new Set(this.triangles.flat());
    for (const v of used) {
      const around = this.triangles.filter((t) => t.includes(v));
      const seen = new Set([0]);
      const queue = [0];
      while (queue.length > 0) {
        const i = queue.shift();
        const others = around[i].filter((x) => x !== v);
        around.forEach((t, j) => {
          if (!seen.has(j) && others.some((o) => t.includes(o))) {
            seen.add(j);
            queue.push(j);
          }
        });
      }
      if (seen.size < around.length) {
        badVertices.push(v);
        problems.push(`not a manifold: the triangles around sample ${v} form several fans`);
      }
    }
    const orientable = badEdges.length > 0 ? false : this.orient();
    if (!orientable && badEdges.length === 0) {
      problems.push('the triangles cannot be oriented consistently (a Möbius-like strip)');
    }
    // Edge-connected components of the triangles.
    const parent = this.triangles.map((_, f) => f);
    const find = (f) => { while (parent[f] !== f) { parent[f] = parent[parent[f]]; f = parent[f]; } return f; };
    const firstOfEdge = new Map();
    this.triangles.forEach((t, f) => {
      for (let k = 0; k < 3; ++k) {
        const key = edgeKey(t[k], t[(k + 1) % 3]);
        if (firstOfEdge.has(key)) parent[find(f)] = find(firstOfEdge.get(key));
        else firstOfEdge.set(key, f);
      }
    });
    const components = new Set(this.triangles.map((_, f) => find(f))).size;
    const unused = this.vertices.filter((v) => !used.has(v)).length;
    if (this.triangles.length === 0) problems.push('no triangles: pick samples, three make a triangle');
    return {
      vertices: used.size,
      unusedVertices: unused,
      edges: byEdge.size,
      triangles: this.triangles.length,
      boundaryEdges,
      components,
      euler: used.size - byEdge.size + this.triangles.length,
      closed: this.triangles.length > 0 && boundaryEdges === 0,
      manifold: badEdges.length === 0 && badVertices.length === 0,
      orientable,
      badEdges,
      badVertices,
      problems,
      ok: problems.length === 0,
    };
  }

  /** The body of POST /api/reconstruct. */
  request() {
    return JSON.stringify({ triangles: this.triangles });
  }

  /**
   * The picked base mesh as an OBJ that `pointform reconstruct --base-mesh` reads: the picked
   * samples' positions (world coordinates, `position(sample)` gives [x, y, z]), each snapped
   * back to its sample when read; the sample indices in comments.
   */
  toObj(position, source) {
    const used = this.vertices.filter((v) => this.triangles.some((t) => t.includes(v)));
    const index = new Map(used.map((v, i) => [v, i + 1]));
    const lines = [
      '# pointform base mesh picked in `pointform view` (paper §5.1, Fig. 6)',
      `# samples: ${source}`,
      '# pointform reconstruct SAMPLES --base-mesh THIS.obj snaps every vertex to its nearest sample',
    ];
    for (const v of used) {
      const p = position(v);
      lines.push(`# sample ${v}`, `v ${p[0]} ${p[1]} ${p[2]}`);
    }
    for (const t of this.triangles) lines.push(`f ${t.map((v) => index.get(v)).join(' ')}`);
    return `${lines.join('\n')}\n`;
  }
}
