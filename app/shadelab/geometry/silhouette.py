"""Shadow-volume geometry: silhouette edges, caps and extrusion to infinity (numpy/trimesh only).

A light is a homogeneous point ``(x, y, z, w)``: ``w = 1`` for point and spot lights, ``w = 0``
for a directional light (``xyz`` = towards the light, i.e. minus its travel direction).

Volume faces are wound counter-clockwise seen from outside the volume, so the stencil pass can
count back faces up and front faces down (z-fail, Carmack's reverse). Extruded vertices are
points at infinity: ``w = 0`` and ``xyz`` = the direction away from the light.

Casters
-------
* Closed, consistently wound meshes (``trimesh`` watertight and winding-consistent) get one
  volume bounded by the silhouette edges (edges between a light-facing and a dark face), a
  near cap made of the dark faces (reversed) and a far cap of the dark faces projected to
  infinity. Using the *dark* side as the near cap keeps the light-facing surface off the
  volume's boundary, so lit faces never self-shadow through depth ties.
* Anything else (open surfaces such as the Cornell box's quads, or inconsistently wound
  meshes) gets one small closed volume per triangle: the triangle turned to face the light
  (near cap), its three edges extruded, and the reversed triangle at infinity (far cap).
  This is always correct (the union of the per-triangle volumes is the shadow) but costs
  more fill than a silhouette volume. Nothing is refused and nothing is "repaired".
  :func:`open_volume` is that union for one or more open casters with the pairs of sides
  that cancel left out (neighbours in one plane that face the light the same way: the
  diagonal of every quad): the same stencil with less fill; the renderer uses it for the
  opaque open casters, grouped by shared corners (:func:`open_caster_groups`).

Per-triangle volumes start beyond their triangle along the light's rays (far enough to be
``offset`` off the triangle's plane, up to ``GRAZING_LIMIT`` offsets at grazing light), so the
lit triangle lies strictly outside its own volume (no self-shadowing acne from depth ties)
while the shadow's outline, made of rays through its edges, stays where it is. Closed casters
need no offset: their lit faces are off the volume's boundary, and the dark faces on it get no
light whatever S_i is (N.L <= 0, or below the terminator fade's threshold on smooth meshes).
An offset there would open a lit gap where the caster touches a receiver (a box standing on a
floor, a sphere's contact point).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shadelab.geometry import cache

GRAZING_LIMIT = 20.0  # per-triangle caps move at most this many offsets along the rays


@dataclass
class ShadowVolume:
    """One caster's shadow volume for one light.

    Attributes
    ----------
    vertices : (2V, 4) float64 homogeneous; rows V.. are the extruded points (w = 0)
    faces : (K, 3) int64 into ``vertices``, counter-clockwise seen from outside the volume
    silhouette : (E, 2) int64 silhouette edges (indices of the first V rows), wound as in
        their light-facing face; every triangle edge in per-triangle mode
    method : "silhouette" | "per-triangle"
    """

    vertices: np.ndarray
    faces: np.ndarray
    silhouette: np.ndarray
    method: str

    def triangles(self) -> np.ndarray:
        """(K, 3, 4) float32 triangle soup for the GPU."""
        return self.vertices[self.faces].astype(np.float32)

    def finite(self, distance: float) -> tuple[np.ndarray, np.ndarray]:
        """The volume with infinity replaced by ``distance`` along each ray (for checks)."""
        v = self.vertices
        n = len(v) // 2
        near = v[:n, :3]
        d = v[n:, :3] / np.maximum(np.linalg.norm(v[n:, :3], axis=1, keepdims=True), 1e-300)
        return np.concatenate([near, near + distance * d]), self.faces


def light_homogeneous(kind: str, position, direction) -> np.ndarray:
    """(4,) homogeneous light position for ``kind`` point | spot | directional."""
    if kind == "directional":
        d = np.asarray(direction, dtype=np.float64)
        return np.append(-d / max(np.linalg.norm(d), 1e-300), 0.0)
    return np.append(np.asarray(position, dtype=np.float64), 1.0)


def away_from_light(points: np.ndarray, light: np.ndarray) -> np.ndarray:
    """(N, 3) unit directions from the light through each point."""
    if light[3] == 0.0:
        return np.broadcast_to(-light[:3], points.shape).copy()
    d = points - light[:3]
    return d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)


def facing_light(vertices: np.ndarray, faces: np.ndarray, light: np.ndarray) -> np.ndarray:
    """(F,) bool: the face's front (counter-clockwise) side sees the light."""
    tri = vertices[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    to_light = light[:3] - light[3] * tri.mean(axis=1)
    return np.einsum("ij,ij->i", normal, to_light) > 0.0


@dataclass
class ClosedMesh:
    """A caster as a closed, consistently wound, outward-facing mesh (trimesh's merge) and
    its face adjacency: what the silhouette needs, cached on disk (:mod:`.cache`)."""

    vertices: np.ndarray              # (V, 3) float64, merged
    faces: np.ndarray                 # (F, 3) int64, outward
    face_adjacency: np.ndarray        # (A, 2) int64 pairs of faces sharing an edge
    face_adjacency_edges: np.ndarray  # (A, 2) int64 the shared edge's vertices


def closed_caster(vertices: np.ndarray, faces: np.ndarray) -> ClosedMesh | None:
    """The caster as a closed, consistently wound, outward-facing mesh, or None."""
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    name = cache.key("closed", vertices, faces)
    hit = cache.load(name)
    if hit is not None and "open" in hit:
        return None
    fields = ("vertices", "faces", "face_adjacency", "face_adjacency_edges")
    if hit is not None and set(fields) <= hit.keys():
        closed = ClosedMesh(*(hit[k] for k in fields))
        if len(closed.faces) and int(closed.faces.max()) < len(closed.vertices):
            return closed
    closed = _closed_with_trimesh(vertices, faces)
    cache.store(name, {"open": np.ones(1)} if closed is None
                else {k: getattr(closed, k) for k in fields})
    return closed


def _closed_with_trimesh(vertices: np.ndarray, faces: np.ndarray) -> ClosedMesh | None:
    import trimesh

    mesh = trimesh.Trimesh(vertices, faces, process=True)
    if len(mesh.faces) == 0 or not (mesh.is_watertight and mesh.is_winding_consistent):
        return None
    if mesh.volume < 0.0:  # wound inside out: same surface, turned
        mesh.invert()
    return ClosedMesh(np.asarray(mesh.vertices, dtype=np.float64),
                      np.asarray(mesh.faces, dtype=np.int64),
                      np.asarray(mesh.face_adjacency, dtype=np.int64),
                      np.asarray(mesh.face_adjacency_edges, dtype=np.int64))


def silhouette_edges(mesh: ClosedMesh, lit: np.ndarray) -> np.ndarray:
    """(E, 2) edges between a light-facing and a dark face, wound as in the lit face."""
    pairs = mesh.face_adjacency
    edges = mesh.face_adjacency_edges
    cross = lit[pairs[:, 0]] != lit[pairs[:, 1]]
    pairs, edges = pairs[cross], edges[cross]
    lit_face = np.where(lit[pairs[:, 0]], pairs[:, 0], pairs[:, 1])
    f = mesh.faces[lit_face]
    a, b = edges[:, 0], edges[:, 1]
    # (a, b) follows the lit face's winding when b comes right after a in it.
    forward = ((f[:, 0] == a) & (f[:, 1] == b)) | ((f[:, 1] == a) & (f[:, 2] == b)) \
        | ((f[:, 2] == a) & (f[:, 0] == b))
    return np.where(forward[:, None], edges, edges[:, ::-1]).astype(np.int64)


def _sides(edges: np.ndarray, n: int) -> np.ndarray:
    """Two triangles per edge (a, b): the quad (b, a, a_inf, b_inf), outward-facing."""
    a, b = edges[:, 0], edges[:, 1]
    return np.concatenate([np.stack([b, a, a + n], 1), np.stack([b, a + n, b + n], 1)])


def _homogeneous(points: np.ndarray, light: np.ndarray, shift: np.ndarray) -> np.ndarray:
    """Near points (moved by ``shift``, w = 1) then the same points at infinity (w = 0)."""
    moved = points + shift
    near = np.concatenate([moved, np.ones((len(points), 1))], axis=1)
    far = np.concatenate([away_from_light(moved, light), np.zeros((len(points), 1))], axis=1)
    return np.concatenate([near, far])


def shadow_volume(vertices: np.ndarray, faces: np.ndarray, light: np.ndarray,
                  offset: float = 0.0) -> ShadowVolume:
    """The shadow volume of one caster (world-space triangles) for one homogeneous light."""
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    mesh = closed_caster(vertices, faces)
    if mesh is not None:
        v = np.asarray(mesh.vertices, dtype=np.float64)
        f = np.asarray(mesh.faces, dtype=np.int64)
        lit = facing_light(v, f, light)
        edges = silhouette_edges(mesh, lit)
        n = len(v)
        dark = f[~lit]
        volume_faces = np.concatenate([_sides(edges, n), dark[:, ::-1], dark + n])
        # No offset: the lit faces are off the volume's boundary (the dark cap), and the dark
        # faces on it get no light whatever S_i is (N.L <= t: the terminator fade). Moving the
        # volume would open a lit gap where the caster touches a receiver (a box on a floor).
        shift = np.zeros_like(v)
        return ShadowVolume(_homogeneous(v, light, shift), volume_faces, edges, "silhouette")
    return per_triangle_volume(vertices, faces, light, offset)


def per_triangle_volume(vertices: np.ndarray, faces: np.ndarray, light: np.ndarray,
                        offset: float = 0.0) -> ShadowVolume:
    """One small closed volume per triangle (any caster; :func:`shadow_volume`'s choice for
    the ones that are not closed): the union of these volumes is the shadow."""
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    # Per-triangle volumes: an unshared triangle soup, each turned to face the light.
    soup, homogeneous = _turned_soup(vertices, faces, light, offset)
    n = len(soup)
    caps = np.arange(n, dtype=np.int64).reshape(-1, 3)
    edges = _soup_edges(caps)
    volume_faces = np.concatenate([_sides(edges, n), caps, caps[:, ::-1] + n])
    contour = edges[_contour_edges(faces, facing_light(vertices, faces, light))]
    return ShadowVolume(homogeneous, volume_faces, contour, "per-triangle")


def _turned_soup(vertices: np.ndarray, faces: np.ndarray, light: np.ndarray,
                 offset: float) -> tuple[np.ndarray, np.ndarray]:
    """The triangles as a soup (3F, 3), each turned to face the light, and the soup's
    homogeneous volume vertices (6F, 4): its caps moved off their triangles, then at infinity.

    Each cap moves along the light's rays (so the shadow's outline does not move) far enough
    to leave ``offset`` between it and its triangle even where the light grazes the surface:
    t = offset / |N.d|, at most GRAZING_LIMIT times offset."""
    tri = vertices[faces]
    lit = facing_light(vertices, faces, light)
    tri = np.where(lit[:, None, None], tri, tri[:, ::-1])
    soup = tri.reshape(-1, 3)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-300)
    away = away_from_light(soup, light)
    cosine = np.abs(np.einsum("ij,ij->i", np.repeat(normal, 3, axis=0), away))
    shift = (offset / np.maximum(cosine, 1.0 / GRAZING_LIMIT))[:, None] * away
    return soup, _homogeneous(soup, light, shift)


def _soup_edges(caps: np.ndarray) -> np.ndarray:
    """(3F, 2) directed edges of the soup's triangles, in the order 01, 12, 20."""
    return np.concatenate([caps[:, [0, 1]], caps[:, [1, 2]], caps[:, [2, 0]]])


def open_volume(parts: list[tuple[np.ndarray, np.ndarray]], light: np.ndarray,
                offset: float) -> ShadowVolume:
    """One volume for open casters (``parts``: (vertices, faces) of one or more meshes): the
    union of their per-triangle volumes with the sides that cancel left out.

    Every triangle is turned to face the light and moved off itself exactly as in the
    per-triangle volumes (:func:`shadow_volume`), so the near caps, far caps and the kept
    sides are those volumes' own faces. Two triangles that share an edge, run along it in
    opposite directions once turned (neighbours that face the light the same way) and moved
    its two corners to the same points (neighbours in one plane: the two halves of a quad,
    coplanar quads that touch) have the same side through it with opposite orientations:
    their counts cancel, so both are left out. The stencil count, a signed sum over the
    faces, is the same everywhere; the long sides through a flat mesh's interior edges are
    gone. Corners are matched by position (and moved point), across the parts too, and the
    volume stays closed edge for edge (no T-junctions): a pair is dropped only where both
    corners are shared vertices. Neighbours at an angle move a shared corner by different
    amounts and keep their sides.
    """
    soups, verts = [], []
    for vertices, faces in parts:
        soup, homogeneous = _turned_soup(np.asarray(vertices, dtype=np.float64),
                                         np.asarray(faces, dtype=np.int64), light, offset)
        soups.append(soup)
        verts.append(homogeneous)
    soup = np.concatenate(soups) if soups else np.zeros((0, 3))
    n = len(soup)
    near = np.concatenate([h[: len(h) // 2] for h in verts]) if verts else np.zeros((0, 4))
    far = np.concatenate([h[len(h) // 2:] for h in verts]) if verts else np.zeros((0, 4))
    # One vertex per corner position and moved point (to 1e-9 of the offset: the two
    # halves of a flat quad compute their equal shifts with different rounding)
    moved = np.linalg.norm(near[:, :3] - soup, axis=1) / max(offset, 1e-300)
    key = np.concatenate([soup, np.round(moved, 9)[:, None]], axis=1)
    _, first, canonical = np.unique(key, axis=0, return_index=True, return_inverse=True)
    canonical = first[canonical.reshape(-1)]
    caps = canonical.reshape(-1, 3)
    edges = _soup_edges(caps)
    first_edge, second_edge = _paired_edges(edges)
    single = np.ones(len(edges), bool)
    single[first_edge] = False
    single[second_edge] = False
    volume_faces = np.concatenate([_sides(edges[single], n), caps, caps[:, ::-1] + n])
    return ShadowVolume(np.concatenate([near, far]), volume_faces.astype(np.int64),
                        edges[single], "open")


def _paired_edges(edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Indices (first, second) into ``edges`` of disjoint pairs of directed edges between the
    same two vertices in opposite directions (a -> b and b -> a)."""
    if len(edges) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    a, b = edges[:, 0], edges[:, 1]
    lo, hi, forward = np.minimum(a, b), np.maximum(a, b), a < b
    # Rank each edge among the edges with the same ends and direction, then pair the k-th
    # a -> b with the k-th b -> a
    order = np.lexsort((forward, hi, lo))
    lo, hi, forward = lo[order], hi[order], forward[order]
    m = len(order)
    new = np.ones(m, bool)
    new[1:] = (lo[1:] != lo[:-1]) | (hi[1:] != hi[:-1]) | (forward[1:] != forward[:-1])
    index = np.arange(m)
    rank = index - np.maximum.accumulate(np.where(new, index, 0))
    again = np.lexsort((forward, rank, hi, lo))
    lo, hi, rank, forward = lo[again], hi[again], rank[again], forward[again]
    pair = ((lo[:-1] == lo[1:]) & (hi[:-1] == hi[1:]) & (rank[:-1] == rank[1:])
            & ~forward[:-1] & forward[1:] & (lo[:-1] != hi[:-1]))
    at = np.flatnonzero(pair)
    sorted_edges = order[again]
    return sorted_edges[at + 1], sorted_edges[at]


def open_caster_groups(parts: list[np.ndarray]) -> list[list[int]]:
    """Indices of ``parts`` (each a (V, 3) vertex array) grouped by shared corner positions:
    casters that touch end up in one group (one :func:`open_volume`)."""
    parent = list(range(len(parts)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    if parts:
        points = np.concatenate([np.asarray(v, dtype=np.float64).reshape(-1, 3) for v in parts])
        owner = np.concatenate([np.full(len(v), i) for i, v in enumerate(parts)])
        _, point = np.unique(points, axis=0, return_inverse=True)
        point = point.reshape(-1)
        first = np.full(point.max() + 1, -1)
        for p, o in zip(point.tolist(), owner.tolist(), strict=True):
            if first[p] < 0:
                first[p] = o
            else:
                ra, rb = root(first[p]), root(o)
                if ra != rb:
                    parent[max(ra, rb)] = min(ra, rb)
    groups: dict[int, list[int]] = {}
    for i in range(len(parts)):
        groups.setdefault(root(i), []).append(i)
    return list(groups.values())


def _contour_edges(faces: np.ndarray, lit: np.ndarray) -> np.ndarray:
    """(3F,) bool over the soup's edges (order 01, 12, 20): boundary edges, and edges whose
    faces disagree about facing the light: the open caster's silhouette, for display."""
    pairs = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    key = np.sort(pairs, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    face_lit = np.tile(lit, 3).astype(np.int64)
    lo = np.full(len(counts), 2)
    hi = np.full(len(counts), -1)
    np.minimum.at(lo, inverse, face_lit)
    np.maximum.at(hi, inverse, face_lit)
    return (counts[inverse] == 1) | (lo[inverse] != hi[inverse])


def shadows_nothing(vertices: np.ndarray, face_normals: np.ndarray, light: np.ndarray,
                    boxes: list[np.ndarray], tolerance: float) -> bool:
    """True when a planar caster's volume holds no receiver, so it can be skipped.

    A flat caster (a floor, a wall: every face normal parallel, every vertex on one plane)
    throws its volume into the half-space behind it, seen from the light. If every corner of
    every receiver's bounding box ``boxes`` ((2, 3) min / max) lies on the light's side of
    the plane (or within ``tolerance`` of it), no receiver surface is inside the volume and
    its stencil count is 0 on every visible pixel: drawing it would only cost fill. The room
    of a Cornell box and the floor under a lecture scene are such casters.
    """
    if len(face_normals) == 0:
        return True
    n = face_normals[0]
    if np.abs(face_normals @ n).min() < 1.0 - 1e-9:
        return False                                  # not flat
    d = float(vertices[0] @ n)
    if np.abs(vertices @ n - d).max() > tolerance:
        return False
    side = float(light[:3] @ n - light[3] * d)        # the light's side of the plane (+/-)
    if abs(side) <= 1e-12:
        return False                                  # a light in the plane: keep it
    if not boxes:
        return True
    stacked = np.stack(boxes)                                       # (M, 2, 3) min / max
    corners = stacked[:, _CORNER_PICK, [0, 1, 2]]                   # (M, 8, 3)
    return not bool(np.any(np.sign(side) * (corners @ n - d) < -tolerance))


_CORNER_PICK = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)])


def box_corners(box: np.ndarray) -> np.ndarray:
    """The 8 corners (8, 3) of a (2, 3) min/max box."""
    return np.asarray(box, dtype=np.float64)[_CORNER_PICK, [0, 1, 2]]


@dataclass
class CountVolume:
    """A silhouette volume with cheaper caps, for the stencil count only (the same counts as
    the full volume wherever :meth:`ranges` says so; shown volumes keep their full caps).

    The count at a point is the winding number of the volume's closed surface around it, a
    sum over its faces that depends on a cap only through the cap's boundary (the silhouette
    loops) and through the points that lie between the cap and its replacement:

    * the far cap (the dark faces at infinity, w = 0) lies at depth 1 in every pixel (z = w
      exactly with the infinite far plane): it is counted wherever it covers the pixel, and
      only its coverage of the screen matters. A fan from one point at infinity over the
      extruded silhouette edges has the same boundary; with every direction from the light
      through the caster in one open hemisphere around the apex (the light outside the
      caster's reach, :func:`count_volume` checks), fan and cap are the same chain on the
      plane at infinity, and cover every pixel the same number of times;
    * the near cap (the dark faces, turned) can become a fan from a point inside the caster
      over the silhouette loops when the caster is convex: the fan lies inside the caster,
      behind its lit faces from the light, and the counts change only between the fan and
      the dark faces, inside the caster, where no visible surface lies while the eye is
      outside the caster (the dark faces themselves count 1 either way: in shadow).

    ``faces`` are [sides, far fan, near fan, near cap (the dark faces, turned)], into
    ``vertices`` (the volume's, then the near apex (w = 1) and the far apex (w = 0)).
    """

    vertices: np.ndarray
    faces: np.ndarray
    sides_and_far: int   # faces: the sides and the far fan
    near_fan: int        # faces: the near fan (0 when the caster is not convex)
    near_cap: int        # faces: the dark faces, turned

    def ranges(self, eye_outside: bool) -> list[tuple[int, int]]:
        """(first face, face count) to draw: the near fan only with the eye outside the
        caster (its bounding box grown by the near plane's reach), else the near cap."""
        if eye_outside and self.near_fan:
            return [(0, self.sides_and_far + self.near_fan)]
        if self.near_fan:
            return [(0, self.sides_and_far),
                    (self.sides_and_far + self.near_fan, self.near_cap)]
        return [(0, self.sides_and_far + self.near_cap)]

    def triangles(self) -> np.ndarray:
        """(K, 3, 4) float32 triangle soup for the GPU."""
        return self.vertices[self.faces].astype(np.float32)


def count_volume(volume: ShadowVolume, light: np.ndarray, convex: bool) -> CountVolume | None:
    """The :class:`CountVolume` of a silhouette volume (:func:`shadow_volume` of a closed
    caster) for the homogeneous ``light``; ``convex``: the caster is convex (its near cap may
    become a fan). None where the caps must stay (no silhouette, or directions from the light
    through the caster that do not fit in an open hemisphere: a light inside or among it) or
    where fans would not be smaller (as many silhouette edges as dark faces: a box)."""
    if volume.method != "silhouette" or len(volume.silhouette) == 0:
        return None
    v = volume.vertices
    n = len(v) // 2
    edges = volume.silhouette
    e = len(edges)
    d = (len(volume.faces) - 2 * e) // 2
    if e >= d:
        return None            # a fan per silhouette edge: no fewer faces than the cap (a box)
    sides = volume.faces[: 2 * e]
    near_cap = volume.faces[2 * e: 2 * e + d]
    directions = v[n:, :3]
    mean = directions.sum(axis=0)
    length = np.linalg.norm(mean)
    if not length > 0.0:
        return None
    mean = mean / length
    if light[3] != 0.0 and float((directions @ mean).min()) <= 1e-6:
        return None            # not within an open hemisphere: keep the far cap
    near_apex = v[np.unique(edges), :3].mean(axis=0)
    vertices = np.concatenate([v, [[*near_apex, 1.0], [*mean, 0.0]]])
    a, b = edges[:, 0], edges[:, 1]
    far_fan = np.stack([np.full(e, 2 * n + 1), b + n, a + n], axis=1)
    near_fan = np.stack([np.full(e, 2 * n), a, b], axis=1) if convex \
        else np.zeros((0, 3), np.int64)
    faces = np.concatenate([sides, far_fan, near_fan, near_cap]).astype(np.int64)
    return CountVolume(vertices, faces, len(sides) + e, len(near_fan), len(near_cap))


def is_convex(vertices: np.ndarray, faces: np.ndarray) -> bool:
    """Is the closed caster (:func:`closed_caster`) convex (trimesh's test)?"""
    import trimesh

    mesh = closed_caster(vertices, faces)
    if mesh is None:
        return False
    return bool(trimesh.Trimesh(mesh.vertices, mesh.faces, process=False).is_convex)


@dataclass
class PlanarOccluder:
    """A flat, opaque caster whose volume only holds what lies behind it (see
    :func:`planar_occluder`): the receivers' parts that its volume can reach, as points, and
    what it takes to see that they are hidden behind the caster itself from an eye."""

    normal: np.ndarray     # (3,) unit normal of the caster's plane, towards the light's side
    d: float               # plane: normal . x = d
    origin: np.ndarray     # (3,) a point of the plane; axes (2, 3): the plane's 2-D frame
    axes: np.ndarray
    hull: np.ndarray       # (H, 2, 2) the outline's edges in the frame, counter-clockwise
    points: np.ndarray     # (P, 3) corners of the receivers' boxes clipped behind the caster

    def hides_volume_from(self, eye: np.ndarray, near_reach: float) -> bool:
        """Is every point the volume can hold hidden from ``eye`` behind the caster itself?
        The eye must be on the light's side, farther from the plane than the near plane
        reaches (which could cut the caster away), and every clipped corner must project
        through the caster's outline onto the eye (with a margin of 1e-9 of the outline)."""
        height = float(eye @ self.normal - self.d)
        if not height > 1.01 * near_reach + 1e-9:
            return False
        if len(self.points) == 0:
            return True
        depth = self.d - self.points @ self.normal          # > 0: behind the plane
        t = height / (height + depth)
        crossing = eye + t[:, None] * (self.points - eye)   # on the plane, between them
        uv = (crossing - self.origin) @ self.axes.T
        a, b = self.hull[:, 0], self.hull[:, 1]
        edge = b - a
        cross = edge[None, :, 0] * (uv[:, None, 1] - a[None, :, 1]) \
            - edge[None, :, 1] * (uv[:, None, 0] - a[None, :, 0])
        scale = max(float(np.abs(self.hull).max()), 1e-300)
        return bool((cross > 1e-9 * scale * np.linalg.norm(edge, axis=1)[None, :]).all())


def planar_occluder(vertices: np.ndarray, faces: np.ndarray, face_normals: np.ndarray,
                    light: np.ndarray, boxes: list[np.ndarray], offset: float,
                    tolerance: float) -> PlanarOccluder | None:
    """The :class:`PlanarOccluder` of an opaque open caster for one homogeneous ``light``, or
    None where it is not one: the caster must be flat (one plane within ``tolerance``, every
    face normal parallel), with a convex outline (its triangles' areas add up to their convex
    hull's), and the light off its plane.

    Its per-triangle volumes (:func:`open_volume`) lie behind the plane as seen from the light,
    their caps moved ``offset`` along the rays (at least ``offset`` min(1, GRAZING_LIMIT |N.d|)
    off the plane). So the receivers' surfaces inside the volume lie inside their boxes
    ``boxes`` ((2, 3) min / max) clipped to the half-space half that distance behind the plane:
    the corners of those clipped boxes are kept. An eye on the light's side that sees each of
    them through the caster sees none of them (the caster is opaque and in front), so no
    visible point is inside the volume and its count is 0 on every pixel: the back wall of the
    lecture's scene, seen from the front.
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    if len(faces) == 0 or len(face_normals) == 0:
        return None
    normal = np.asarray(face_normals[0], dtype=np.float64)
    normal = normal / max(np.linalg.norm(normal), 1e-300)
    if np.abs(face_normals @ normal).min() < 1.0 - 1e-9:
        return None
    d = float(vertices[faces[0, 0]] @ normal)
    if np.abs(vertices @ normal - d).max() > tolerance:
        return None
    side = float(light[:3] @ normal - light[3] * d)
    if abs(side) <= 1e-12:
        return None
    if side < 0.0:
        normal, d = -normal, -d
    # the plane's frame and the outline
    helper = np.eye(3)[int(np.argmin(np.abs(normal)))]
    u = np.cross(normal, helper)
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    axes = np.stack([u, v])
    origin = d * normal
    used = np.unique(faces)
    flat = (vertices[used] - origin) @ axes.T
    hull = _convex_hull_2d(flat)
    if len(hull) < 3:
        return None
    tri = (vertices[faces] - origin) @ axes.T
    ab, ac = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    areas = 0.5 * np.abs(ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0]).sum()
    hull_area = 0.5 * abs(float(np.sum(hull[:, 0] * np.roll(hull[:, 1], -1)
                                       - np.roll(hull[:, 0], -1) * hull[:, 1])))
    if not abs(areas - hull_area) <= 1e-9 * max(hull_area, 1e-300):
        return None
    # how far behind the plane the volume starts, at the least
    away = away_from_light(vertices[used], light)
    cosine = float(np.abs(away @ normal).min())
    behind = 0.5 * offset * min(1.0, GRAZING_LIMIT * cosine) - tolerance
    if not behind > 0.0:
        return None
    points = [_box_behind(box, normal, d - behind) for box in boxes]
    points = np.concatenate(points) if points else np.zeros((0, 3))
    edges = np.stack([hull, np.roll(hull, -1, axis=0)], axis=1)
    return PlanarOccluder(normal, d, origin, axes, edges, points)


def _box_behind(box: np.ndarray, normal: np.ndarray, level: float) -> np.ndarray:
    """Corners of the (2, 3) box clipped to ``normal . x <= level``: the box's corners there
    and where its edges cross the plane (the clipped box is their convex hull)."""
    corners = box_corners(box)                                                # (8, 3)
    height = corners @ normal - level
    keep = [corners[height <= 0.0]]
    for i in range(8):
        for j in range(i + 1, 8):
            if bin(i ^ j).count("1") != 1:
                continue                                   # not an edge of the box
            hi, hj = height[i], height[j]
            if (hi < 0.0 < hj) or (hj < 0.0 < hi):
                t = hi / (hi - hj)
                keep.append((corners[i] + t * (corners[j] - corners[i]))[None])
    return np.concatenate(keep)


def _convex_hull_2d(points: np.ndarray) -> np.ndarray:
    """(H, 2) convex hull, counter-clockwise, no collinear points (Andrew's monotone chain)."""
    pts = np.unique(np.round(points, 12), axis=0)
    if len(pts) < 3:
        return pts

    def turn(o, a, b) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list = []
    for p in pts:
        while len(lower) >= 2 and turn(lower[-2], lower[-1], p) <= 0.0:
            lower.pop()
        lower.append(p)
    upper: list = []
    for p in pts[::-1]:
        while len(upper) >= 2 and turn(upper[-2], upper[-1], p) <= 0.0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])


# A bounded volume's far points lie on a face of the receivers' box grown by this share of its
# diagonal (beyond every receiver by far more than a depth step; see bounded_volume)
BOUND_MARGIN = 0.02
BOUND_MIN_COSINE = 1e-3   # a ray must leave through the chosen face at least this steeply


def volume_sources(n: int, count_volume_rows: bool = False) -> np.ndarray:
    """For each row of a silhouette or per-triangle volume's vertices (``n`` near points,
    then their ``n`` points at infinity; with ``count_volume_rows``, then a
    :class:`CountVolume`'s near apex and far apex): the row of the near point its ray
    starts from (a near row: itself)."""
    rows = [np.arange(n), np.arange(n)]
    if count_volume_rows:
        rows.append(np.array([2 * n, 2 * n]))
    return np.concatenate(rows).astype(np.int64)


def bounded_volume(vertices: np.ndarray, sources: np.ndarray, box: np.ndarray,
                   margin: float) -> tuple[np.ndarray, int, float] | None:
    """The volume with its points at infinity brought in to a face of the receivers' ``box``
    (2, 3) grown by ``margin``: each ray from its near point (``sources``, see
    :func:`volume_sources`) stops where it leaves through that face. Where a near point lies
    within half a margin of the face (or past it), the plane moves out to half a margin past
    the near points, at most one more margin. Returns (vertices (M, 4), all w = 1; the face as
    axis * 2 + side; the farthest a ray runs), or None where no face is crossed by every ray
    at least BOUND_MIN_COSINE steeply, or a near point lies farther out.

    For every point of the box, the count (the winding number of the closed surface) is the
    same: what is cut off, the rays' ends beyond the face and the cap at infinity closed by
    the new cap on the face, is a closed surface all on the far side of the face, and winds
    0 times around anything on the near side. The caps keep their topology, being the
    central projection onto the face of the directions, all in the open hemisphere the face
    looks into. The sides then end past the last receiver instead of running on across the
    screen (far less stencil fill, issue 25); z-fail counts the same because its rays from a
    visible point run to the far cap wherever it is, and no clip plane cuts a finite volume
    with depth clamp on."""
    v = np.asarray(vertices, dtype=np.float64)
    far = v[:, 3] == 0.0
    if not far.any():
        return None
    starts = v[sources[far], :3]
    directions = v[far, :3] / np.maximum(np.linalg.norm(v[far, :3], axis=1, keepdims=True),
                                         1e-300)
    near = v[~far, :3]
    grown = np.stack([box[0] - margin, box[1] + margin])
    best = None
    for axis in range(3):
        for side, sign in ((0, -1.0), (1, 1.0)):
            level = sign * grown[side, axis]            # plane: sign * x[axis] = level
            slope = sign * directions[:, axis]
            if slope.min() < BOUND_MIN_COSINE:
                continue
            # a near point within half a margin of the face (a caster standing on the
            # floor, its caps moved along the rays, GRAZING_LIMIT offsets at most): the
            # plane moves out up to one more margin, still beyond every receiver
            plane = max(level, (sign * near[:, axis]).max(initial=-np.inf) + 0.5 * margin)
            if plane > level + margin:
                continue
            t = (plane - sign * starts[:, axis]) / slope
            reach = float(t.max())
            if best is None or reach < best[0]:
                best = (reach, axis, side, t, plane)
    if best is None:
        return None
    reach, axis, side, t, plane = best
    out = v.copy()
    out[far, :3] = starts + t[:, None] * directions
    out[far, 3] = 1.0
    out[far, axis] = (1.0 if side else -1.0) * plane  # exactly on the plane
    return out, 2 * axis + side, reach
