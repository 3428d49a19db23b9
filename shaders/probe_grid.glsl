// probes::ProbeGrid's arithmetic on a ProbeGridGpu (transgi_shared.h):
// storage is toroidal (scroll), grid coordinate (0,0,0) sits at `min`.
vec3 grid_min(ProbeGridGpu g) { return vec3(g.min_x, g.min_y, g.min_z); }
vec3 grid_spacing(ProbeGridGpu g) { return vec3(g.spacing_x, g.spacing_y, g.spacing_z); }
ivec3 grid_dims(ProbeGridGpu g) { return ivec3(g.dims_x, g.dims_y, g.dims_z); }

// ProbeGrid::index: the storage index of grid coordinates c (in [0, dims)).
int grid_index(ProbeGridGpu g, ivec3 c) {
  const ivec3 dims = grid_dims(g);
  c += ivec3(g.scroll_x, g.scroll_y, g.scroll_z);
  c -= ivec3(greaterThanEqual(c, dims)) * dims;
  return (c.z * dims.y + c.y) * dims.x + c.x;
}

// ProbeGrid::coords: the grid coordinates of storage index i.
ivec3 grid_coords(ProbeGridGpu g, int i) {
  const ivec3 dims = grid_dims(g);
  ivec3 c = ivec3(i % dims.x, (i / dims.x) % dims.y, i / (dims.x * dims.y));
  c -= ivec3(g.scroll_x, g.scroll_y, g.scroll_z);
  c += ivec3(lessThan(c, ivec3(0))) * dims;
  return c;
}
