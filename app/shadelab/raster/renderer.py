"""The raster renderer: a Scene drawn as an ordered list of passes into a RenderTarget.

Geometry lives on the GPU keyed by each object's geometry (:func:`geometry_key`), so a slider
that changes a coefficient re-sets uniforms only; nothing is re-uploaded.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, replace

import moderngl
import numpy as np

from shadelab.geometry.mesh import MeshData, geometry_key, object_mesh, scene_bounds
from shadelab.geometry.silhouette import box_corners
from shadelab.gl import programs as gl_programs
from shadelab.gl.programs import (
    UniformCache,
    load_program,
    set_uniform,
    set_uniform_array,
    stock_include,
)
from shadelab.gl.target import RenderTarget
from shadelab.gl.vertex import soup_vertex_array, triangle_soup
from shadelab.raster.memo import memoized
from shadelab.raster.painter import draw_painter
from shadelab.raster.textures import TextureCache, has_surface_detail
from shadelab.raster.transparency import draw_transparent
from shadelab.scene.camera import clip_from_world, far_plane, gl_matrix, tan_half_fov_y
from shadelab.scene.model import MAX_LIGHTS, Light, Material, Scene
from shadelab.shading.codes import ATTENUATION_CODES, CODE_BITS, SPECULAR_CODES, TERM_BITS
from shadelab.shading.lights import light_kind
from shadelab.shading.packing import (
    PackedMaterial,
    light_uniform_arrays,
    material_key,
    material_uniforms,
    pack_material,
    premultiplied_uniforms,
)

SHADING_PROGRAMS = ("flat", "gouraud", "phong")
# Variants with texture-mapped Od and bump maps (a geometry shader adds the tangents); only
# materials with a texture or a bump use them, so every other material keeps its output.
TEXTURED_PROGRAMS = {name: f"{name}_tex" for name in SHADING_PROGRAMS}
# The programs whose Od is the material's u_Od: compiled with PREMULTIPLIED (lighting.glsl), so
# the per-material, per-light factors are folded here once instead of read per fragment.
PREMULTIPLIED = {"PREMULTIPLIED": 1}
# Materials whose specular term is 0 everywhere (ks = 0, or the term switched off) are drawn
# with a "<program>:diffuse" twin compiled with NO_SPECULAR (lighting.glsl): the lobe's pow is
# never evaluated, and the image is the same bit for bit (its product with ks Os = 0 was +0).
# False: every material with the full program (for A/B measurements and tests)
DIFFUSE_VARIANTS = True
DIFFUSE_SUFFIX = ":diffuse"
# Opaque closed meshes seen from outside are drawn with their back faces culled
# (Renderer.cullable); False draws every face (for A/B measurements and tests)
BACK_FACE_CULLING = True
# One light with shadow volumes (and no transparent caster): the first pass draws ambient plus
# that light everywhere, depth written; after the stencil count the ambient-only programs write
# over the pixels whose count is not 0 (Renderer._lit_first_passes). No ambient pass over the
# whole frame and no blending: the image is the same bit for bit (ambient + x is x + ambient;
# Gouraud within float rounding). False: the ambient pass, the count, then the light added where
# the count is 0, as for several lights (for A/B measurements and tests)
LIT_FIRST = True
# ... and that first pass draws the meshes nearest first (_near_first), so llvmpipe's early
# depth test skips shading what they hide; False: scene order (A/B measurements, tests)
NEAR_FIRST = True
# ... and the ambient-only pass over the shadow is scissored to the rectangle the shadow volumes
# cover on screen (ShadowVolumes.screen_rect); False: the whole frame (A/B runs, tests)
SCISSOR_SHADOW = True


class ProgramVariant(dict):
    """One light configuration's shading programs by name, each compiled on first use: a
    frame draws with one or two of the six (its shading mode, and its textured twin where a
    material has surface detail), and every compile costs start-up time on llvmpipe."""

    def __init__(self, ctx: moderngl.Context, defines: dict[str, object]):
        super().__init__()
        self.ctx = ctx
        self.defines = defines

    def __missing__(self, name: str) -> moderngl.Program:
        base, _, twin = name.partition(DIFFUSE_SUFFIX[0])
        if twin and twin != DIFFUSE_SUFFIX[1:]:
            raise KeyError(name)
        if base in TEXTURED_PROGRAMS.values() and not twin:
            program = load_program(self.ctx, name, self.defines)
        elif base in SHADING_PROGRAMS:
            # ShadeLab's lighting chunk: the plain programs premultiplied; a replaced chunk (a
            # student's, registered by load_program as it compiles) reads its own uniforms and
            # knows no NO_SPECULAR: its diffuse twin is its own program, not compiled again
            gl_programs.register_includes(self.ctx)
            stock = stock_include(self.ctx, "lighting")
            if twin and not stock:
                program = self[base]
            else:
                fast = PREMULTIPLIED if stock else {}
                diffuse = {"NO_SPECULAR": 1} if twin else {}
                program = load_program(self.ctx, base, {**self.defines, **fast, **diffuse})
        else:
            raise KeyError(name)
        self[name] = program
        return program


@dataclass
class GpuMesh:
    """One object's triangle soup on the GPU, with one VAO per shading program."""

    key: tuple
    mesh: MeshData
    vbo: moderngl.Buffer
    vaos: dict[tuple, moderngl.VertexArray]  # by (program name, (light signature, terminator))
    bounds: np.ndarray  # (2, 3) min and max corner, world space, computed once at upload

    def release(self) -> None:
        for vao in self.vaos.values():
            vao.release()
        self.vbo.release()


@dataclass
class View:
    """Camera matrices for one frame (column vectors: ``p_clip = clip_from_world @ p_world``)."""

    clip_from_world: np.ndarray
    eye: np.ndarray
    size: tuple[int, int]
    # how far from the eye the near plane reaches (:func:`near_reach`); inf: unknown, and
    # nothing is taken to be seen from outside
    near_reach: float = math.inf
    near: float = 0.0  # the near plane's distance (0: unknown; the depth steps follow from it)


class ProgramUniforms:
    """One shading program's uniform cache and the frame state its premultiplied material
    uniforms are folded from (the lights as drawn, S_i included, Ia and the ambient switch)."""

    def __init__(self, program: moderngl.Program):
        self.cache = UniformCache(program)
        self.premultiplied = "u_ambient" in self.cache or "u_light_diffuse" in self.cache
        self.lights_key: object = None
        self.ip_s = np.zeros((MAX_LIGHTS, 3))  # S_i Ip,i per light, padded
        self.Ia = np.zeros(3)
        self.Ia_values: tuple = ()
        self.view: View | None = None  # the view whose matrix and eye the program holds
        self.ambient_on = 1.0
        self.terms_off = 0      # the u_terms_off bits (TERM_AMBIENT is folded into u_ambient)
        self.materials: dict[tuple, list[tuple[str, bytes]]] = {}  # folded writes, per frame


def make_view(scene: Scene, size: tuple[int, int], meshes: list[MeshData],
              infinite_far: bool = False, bounds: np.ndarray | None = None) -> View:
    """The scene camera's view for an image of ``size`` = (width, height) pixels.

    ``bounds`` (2, 3), when the caller has them, spares scanning every vertex of ``meshes``.
    """
    aspect = size[0] / size[1]
    if bounds is None:
        bounds = scene_bounds(meshes)
    far = math.inf if infinite_far else far_plane(scene.camera, bounds)
    eye = np.asarray(scene.camera.eye, dtype=np.float64)
    return View(clip_from_world(scene.camera, aspect, far), eye, size,
                near_reach(scene, size), float(scene.camera.near))


class Renderer:
    """Draws a Scene with flat, Gouraud or Phong shading on any moderngl context."""

    def __init__(self, ctx: moderngl.Context, exact: bool = False):
        self.ctx = ctx
        # exact: the lecture's equation as written, no terminator fade in the shadow-volume
        # lit pass (u_terminator = 0): what a course's reference images are rendered with
        self.exact = exact
        self._variants: dict[tuple, dict[str, moderngl.Program]] = {}
        self._uniforms: dict[moderngl.Program, ProgramUniforms] = {}
        self._light_arrays: dict[str, tuple[str, dict[str, np.ndarray]]] = {}
        self._view_key: tuple | None = None
        self._view: View | None = None  # the last view_for, while its key holds
        self._matrix: tuple[View, bytes] | None = None  # the last view's matrix, packed
        self._bounds: tuple | None = None  # (mesh ids, their union box, the meshes)
        self._batches: dict[tuple, GpuMesh] = {}  # runs of meshes of one material, merged
        self._detail = False  # a material of the scene drawn has surface detail (render)
        self._twins = False   # the frame draws ks = 0 materials with the diffuse twins
        self._diffuse = False  # ... and a material of the scene drawn is one (render)
        self.light_signature: tuple = ((), "phong")
        self._variant_key: tuple = (self.light_signature, False)
        self.programs = self.programs_for_lights([], "phong")
        self.textures = TextureCache(ctx)
        self._gpu: dict[int, GpuMesh] = {}
        self._shadows = None  # shadelab.raster.shadows.ShadowVolumes, made on first use
        self.terms_off = 0    # the frame's u_terms_off bits (render's ``terms_off``)
        self._outward: dict[tuple, bool] = {}  # geometry key -> closed, wound outward (culling)
        self._culled: frozenset[int] = frozenset()  # id() of the frame's back-face-culled meshes

    @staticmethod
    def light_signature_of(lights: list[Light], specular: str) -> tuple:
        """What a program variant is compiled for: each light's (kind, attenuation) codes."""
        codes = tuple((light_kind(light).code, ATTENUATION_CODES[light.attenuation])
                      for light in lights[:MAX_LIGHTS])
        return codes, specular

    @staticmethod
    def light_defines(signature: tuple) -> dict[str, object]:
        """The ``#define``s of ``lighting.glsl`` for a light signature (CODE_BITS = 2 bits per
        light)."""
        codes, model = signature
        kinds = sum(kind << (CODE_BITS * i) for i, (kind, _) in enumerate(codes))
        attenuations = sum(att << (CODE_BITS * i) for i, (_, att) in enumerate(codes))
        return {"NUM_LIGHTS": len(codes), "LIGHT_KINDS": f"{kinds}u",
                "LIGHT_ATTENUATIONS": f"{attenuations}u",
                "SPECULAR_MODEL": SPECULAR_CODES[model]}

    def programs_for_lights(self, lights: list[Light], specular: str,
                            terminator: bool = False) -> ProgramVariant:
        """Every shading program for this light configuration (cached; each compiled on first
        use, :class:`ProgramVariant`).

        Positions, colors and coefficients stay uniforms, so sliders never recompile; adding
        a light or changing a light's kind or attenuation mode compiles a new variant once.
        Passes that draw a subset of the lights (the shadow passes) switch the others off with
        their shadow factor S_i = 0. ``terminator``: the variant of the shadow-volume lit pass,
        which fades S_i by each point's threshold (lighting.glsl's TERMINATOR, switched by
        u_terminator); every other pass has none to fade and leaves the term out, and so does
        a replaced lighting chunk (a student's) without lighting.glsl's TERMINATOR blocks.
        """
        signature = self.light_signature_of(lights, specular)
        key = (signature, terminator)
        if key not in self._variants:
            defines = self.light_defines(signature)
            if terminator and _chunk_fades(self.ctx):
                defines["TERMINATOR"] = 1
            self._variants[key] = ProgramVariant(self.ctx, defines)
        return self._variants[key]

    def uniforms(self, program: moderngl.Program) -> ProgramUniforms:
        """The uniform cache of one of this renderer's programs (made on first use)."""
        state = self._uniforms.get(program)
        if state is None:
            state = self._uniforms[program] = ProgramUniforms(program)
        return state

    def use_lights(self, lights: list[Light], specular: str, terminator: bool = False) -> None:
        """Make ``self.programs`` the variant for these lights (once per frame)."""
        self.light_signature = self.light_signature_of(lights, specular)
        self._variant_key = (self.light_signature, terminator)
        self.programs = self.programs_for_lights(lights, specular, terminator)

    def vao(self, gpu: GpuMesh, program_name: str) -> moderngl.VertexArray:
        """The object's VAO for a program of the current light variant (made lazily)."""
        key = (program_name, self._variant_key)
        vao = gpu.vaos.get(key)
        if vao is None:
            vao = soup_vertex_array(self.ctx, self.programs[program_name], gpu.vbo)
            gpu.vaos[key] = vao
        return vao

    # ------------------------------------------------------------ geometry
    def sync(self, scene: Scene) -> list[GpuMesh]:
        """Upload objects whose geometry changed; reuse the rest."""
        live = []
        for index, obj in enumerate(scene.objects):
            key = geometry_key(obj, scene.base_dir)
            gpu = self._gpu.get(index)
            if gpu is None or gpu.key != key:
                self._release_batches()
                if gpu is not None:
                    gpu.release()
                gpu = self._upload(key, object_mesh(obj, index, scene.base_dir))
                self._gpu[index] = gpu
            gpu.mesh.material = obj.material
            live.append(gpu)
        for index in [i for i in self._gpu if i >= len(scene.objects)]:
            self._release_batches()
            self._gpu.pop(index).release()
        return live

    def _upload(self, key: tuple, mesh: MeshData) -> GpuMesh:
        vbo = self.ctx.buffer(triangle_soup(mesh).tobytes())
        bounds = np.stack([mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)])
        return GpuMesh(key, mesh, vbo, {}, bounds)  # VAOs: per program variant, lazily

    # ------------------------------------------------------------ uniforms
    def variants(self, shading: str) -> list[moderngl.Program]:
        """The shading mode's program and, where a material has surface detail, its textured
        variant, and where a material has no specular term, its diffuse twin: the programs
        this frame's passes draw with."""
        names = [shading]
        if self._diffuse:
            names.append(shading + DIFFUSE_SUFFIX)
        if self._detail:
            names.append(TEXTURED_PROGRAMS[shading])
        return [self.programs[name] for name in names]

    def program_for(self, shading: str, material: Material) -> str:
        """Name of the program that draws ``material`` in ``shading`` mode: the textured one
        for surface detail, the diffuse twin where the specular term is 0 everywhere
        (:func:`diffuse_only`), else the mode's own."""
        if has_surface_detail(material):
            return TEXTURED_PROGRAMS[shading]
        if self._twins and diffuse_only(material, self.terms_off):
            return shading + DIFFUSE_SUFFIX
        return shading

    def use_material(self, scene: Scene, name: str, shading: str) -> str:
        """Set one material's uniforms (and textures) on its program; returns the program name."""
        material = scene.materials[name]
        program_name = self.program_for(shading, material)
        program = self.programs[program_name]
        self.write_material(program, material)
        if program_name != shading:
            self.textures.bind(program, name, material, scene.base_dir)
        return program_name

    def set_frame_uniforms(self, program: moderngl.Program, scene: Scene, view: View,
                           specular: str, lights: list[Light] | None = None,
                           ambient_on: float = 1.0) -> None:
        """Camera, ambient, specular model and the lights (the scene's active ones unless
        ``lights`` is given, as the shadow passes do one light at a time); ``ambient_on`` 0
        leaves Le + Ia ka Od out (the shadow passes' added lights). Written only if changed."""
        state = self.uniforms(program)
        cache = state.cache
        if state.view is not view:
            cache.write("u_clip_from_world", self._view_matrix(view))
            cache.write("u_eye", struct.pack("3f", *view.eye))
            state.view = view
        Ia = tuple(scene.Ia)
        if Ia != state.Ia_values:
            state.Ia_values, state.Ia = Ia, np.asarray(Ia, dtype=np.float64)
            cache.write("u_Ia", struct.pack("3f", *Ia))
        cache.write("u_specular_model", struct.pack("i", SPECULAR_CODES[specular]))
        cache.write("u_terms_off", struct.pack("i", self.terms_off))
        self.set_frame_lights(program, scene.active_lights() if lights is None else lights,
                              ambient_on)

    def set_frame_lights(self, program: moderngl.Program, lights: list[Light],
                         ambient_on: float = 1.0) -> None:
        """The ``u_light_*`` arrays and the ambient switch, through the program's cache; the
        premultiplied material uniforms are folded from them at the next draw."""
        state = self.uniforms(program)
        key, arrays = self._lights_packed(lights)
        frame = (key, state.Ia_values, ambient_on, self.terms_off)
        if frame == state.lights_key:
            return  # what the cache wrote last time
        for name, array in arrays.items():
            state.cache.write_array(name, array)
        state.cache.write("u_ambient_on", struct.pack("f", ambient_on))
        state.lights_key = frame
        state.ip_s = (arrays["u_light_Ip"].astype(np.float64)
                      * arrays["u_light_S"].astype(np.float64)[:, None])
        state.ambient_on = ambient_on
        state.terms_off = self.terms_off
        state.materials.clear()

    def _lights_packed(self, lights: list[Light]) -> tuple[str, dict[str, np.ndarray]]:
        """:func:`light_uniform_arrays` of ``lights``, kept while the lights' values stay."""
        key = repr(lights)
        packed = self._light_arrays.get(key)
        if packed is None:
            if len(self._light_arrays) > 64:
                self._light_arrays.clear()
            packed = self._light_arrays[key] = (key, light_uniform_arrays(lights))
        return packed

    def _view_matrix(self, view: View) -> bytes:
        if self._matrix is None or self._matrix[0] is not view:
            self._matrix = (view, gl_matrix(view.clip_from_world))
        return self._matrix[1]

    def view_for(self, scene: Scene, size: tuple[int, int], gpu_meshes: list[GpuMesh],
                 infinite_far: bool) -> View:
        """:func:`make_view`, kept while the camera, size, far plane and bounds stay."""
        ids = tuple(map(id, gpu_meshes))
        if self._bounds is None or self._bounds[0] != ids:
            # the memo keeps the meshes alive, so their ids stay theirs
            self._bounds = (ids, _union_bounds([g.bounds for g in gpu_meshes]), gpu_meshes)
        bounds = self._bounds[1]
        camera = scene.camera
        key = (tuple(camera.eye), tuple(camera.target), tuple(camera.up), camera.fov_y,
               camera.near, tuple(size), infinite_far,
               None if bounds is None else bounds.tobytes())
        if key != self._view_key or self._view is None:
            self._view = make_view(scene, size, [g.mesh for g in gpu_meshes], infinite_far,
                                   bounds)
            self._view_key = key
        return self._view

    def write_material(self, program: moderngl.Program, material: Material) -> None:
        """One material's uniforms through the program's cache: the raw coefficients where the
        program reads them, the folded u_ambient, u_light_diffuse, u_light_specular where it is
        PREMULTIPLIED (computed once per material and frame state)."""
        state = self.uniforms(program)
        values = material_key(material)
        writes = state.materials.get(values)
        if writes is None:
            if len(state.materials) > 256:  # a slider sweeping a coefficient
                state.materials.clear()
            writes = state.materials[values] = _material_writes(state, pack_material(material))
        for name, data in writes:
            state.cache.write(name, data)

    @staticmethod
    def set_material_uniforms(program: moderngl.Program, material: Material) -> None:
        """The raw material uniforms (no cache, no folding): the same bytes
        :meth:`write_material` writes, from :func:`shadelab.shading.packing.material_uniforms`."""
        for name, data in material_uniforms(pack_material(material)).items():
            set_uniform(program, name, data)

    # ------------------------------------------------------------ passes
    def render(self, scene: Scene, target: RenderTarget, shading: str | None = None,
               specular: str | None = None, terms_off: int = 0) -> View:
        """Draw one frame into ``target``; returns the view used. ``terms_off``: the
        equation's terms left out (:data:`shadelab.shading.codes.TERM_BITS`, lighting.glsl's
        ``u_terms_off``); with the shadow term off the shadow volumes' stencil passes are
        skipped (S_i = 1) and only their teaching overlays stay."""
        self.terms_off = int(terms_off)
        shading = shading or scene.render.shading
        specular = specular or scene.render.specular
        settings = scene.render
        gpu_meshes = self.sync(scene)
        self._detail = any(has_surface_detail(m) for m in scene.materials.values())
        self._twins = DIFFUSE_VARIANTS
        self._diffuse = self._twins and any(
            diffuse_only(m, self.terms_off) and not has_surface_detail(m)
            for m in scene.materials.values())
        lights = scene.active_lights()[:MAX_LIGHTS]
        self.use_lights(lights, specular)
        painter = settings.visibility == "painter"
        volumes_on = settings.shadows == "volumes" and bool(lights) and not painter
        shadowed = volumes_on and not self.terms_off & TERM_BITS["shadow"]
        # Shadow volumes reach infinity (w = 0): the whole frame then uses an infinite far plane.
        view = self.view_for(scene, target.size, gpu_meshes, volumes_on)
        opaque = [g for g in gpu_meshes if not is_transparent(scene.materials[g.mesh.material])]
        clear = [g for g in gpu_meshes if is_transparent(scene.materials[g.mesh.material])]
        self._culled = frozenset(id(g) for g in opaque if BACK_FACE_CULLING
                                 and self.cullable(g, scene, target.size))
        # --- PASS 1: clear color, depth and stencil
        target.clear(settings.background)
        if painter:
            # --- PASS 2 (list priority): every triangle back to front, no depth test
            for variant in self.variants(shading):
                self.set_frame_uniforms(variant, scene, view, specular)
            draw_painter(self, scene, gpu_meshes, shading, view)
            return view
        if shadowed and self._lit_first(scene, lights):
            # --- PASSES 2-3, one light: ambient + the light everywhere, its stencil count,
            #     then ambient alone written over where the count is not 0
            self._lit_first_passes(scene, target, view, gpu_meshes, opaque, lights[0],
                                   shading, specular)
        else:
            # --- PASS 2: opaque surfaces, ambient + every light in one pass (S_i = 1);
            #     with shadow volumes: ambient + emission only (the lights come in pass 3)
            self.ctx.enable_only(moderngl.DEPTH_TEST)
            if shadowed:
                self.use_lights([], specular)  # programs with no light loop: ambient + Le
            for variant in self.variants(shading):
                self.set_frame_uniforms(variant, scene, view, specular)
            self.draw_objects(scene, opaque, shading)
            if shadowed:
                self.use_lights(lights, specular)
                for variant in self.variants(shading):
                    self.set_frame_uniforms(variant, scene, view, specular)
            # --- PASS 3: per light, a stencil count of its shadow volumes (z-fail or
            #     z-pass), then that light alone added where the count is 0 (S_i = 1)
            if shadowed:
                from shadelab.gl.lite import glFlush

                # llvmpipe rasterizes pass 2 on its threads while this thread bins the
                # volumes and the lit passes (else all of them wait for the display pass)
                glFlush()
                self._shadow_passes(scene, target, view, gpu_meshes, opaque, lights,
                                    shading, specular)
        # --- PASS 4: transparent surfaces back to front, blended by their model
        #     (interpolated or filtered), depth-tested against the opaque ones
        if clear:
            for variant in self.variants(shading):
                self.set_frame_uniforms(variant, scene, view, specular)
            draw_transparent(self, scene, clear, shading, view)
        # --- PASS 5: teaching overlays: stencil heat map, translucent volumes, silhouettes
        if volumes_on and (settings.stencil_heatmap or settings.show_volumes
                           or settings.show_silhouettes):
            self._shadow_overlays(scene, target, view, gpu_meshes, lights)
        self.ctx.enable_only(moderngl.DEPTH_TEST)
        return view

    @property
    def shadow_volumes(self):
        """The stencil shadow-volume helper (made on first use)."""
        if self._shadows is None:
            from shadelab.raster.shadows import ShadowVolumes

            self._shadows = ShadowVolumes(self.ctx)
        return self._shadows

    def _lit_first(self, scene: Scene, lights: list[Light]) -> bool:
        """Can the shadowed frame take :meth:`_lit_first_passes`? One light, and no
        transparent object casting a shadow (its kt filter needs the flags' passes)."""
        return LIT_FIRST and len(lights) == 1 and not any(
            obj.cast_shadows and is_transparent(scene.materials[obj.material])
            for obj in scene.objects)

    def _lit_first_passes(self, scene: Scene, target: RenderTarget, view: View, gpu_meshes,
                          opaque, light: Light, shading: str, specular: str) -> None:
        """One light's shadowed frame in three passes: ambient + the light everywhere (the
        lit pass's programs, terminator fade included, ambient on; depth written), the
        light's stencil count, then the ambient-only programs over the pixels whose count is
        not 0 (S = 0 there: ambient + 0). The sum ambient + light is the one the additive
        pass makes, in the other order: the same floats (Gouraud: within float rounding, its
        colors interpolated as one sum)."""
        from shadelab.gl.lite import glFlush

        self.ctx.enable_only(moderngl.DEPTH_TEST)
        self.use_lights([light], specular, terminator=True)
        for variant in self.variants(shading):
            self.set_frame_uniforms(variant, scene, view, specular, [light], ambient_on=1.0)
        self.draw_objects(scene, _near_first(opaque, view.eye) if NEAR_FIRST else opaque,
                          shading, terminator=True)
        for variant in self.variants(shading):   # this light's variant: fade off again
            set_uniform(variant, "u_terminator", 0.0)
        glFlush()   # llvmpipe rasterizes it while this thread bins the volumes
        shadows = self.shadow_volumes
        shadows.drop_lights_from(1)
        volumes = shadows.volumes(scene, gpu_meshes, 0, light)
        shadows.count(target, view, volumes, scene.render.shadow_method, clear=False)
        self.ctx.enable_only(moderngl.DEPTH_TEST)
        self.ctx.depth_func = "<="
        shadows.where_not_zero()
        # the ambient-only programs (no light loop: Le + Ia ka Od, u_ambient premultiplied),
        # what the lit programs write where S = 0; their vertex shader is the lit pass's
        # (invariant gl_Position), so "<=" passes exactly where pass 2 drew. Only the pixels in
        # shadow run them, without the varyings and the light's math the lit programs carry
        self.use_lights([], specular)
        for variant in self.variants(shading):
            self.set_frame_uniforms(variant, scene, view, specular, [], ambient_on=1.0)
        # ... within the rectangle that holds the volumes' pixels (no count elsewhere)
        rect = shadows.screen_rect(view, volumes, scene.render.shadow_method) \
            if SCISSOR_SHADOW else None
        if rect is None or rect[2] * rect[3] > 0:
            target.fbo.scissor = rect
            target.fbo.use()
            self.draw_objects(scene, opaque, shading)
            target.fbo.scissor = None
        shadows.stencil_off()
        self.use_lights([light], specular)
        self.ctx.depth_func = "<"
        target.fbo.depth_mask = True
        target.fbo.use()
        for variant in self.variants(shading):
            self.set_frame_lights(variant, [light], ambient_on=1.0)

    def _shadow_passes(self, scene: Scene, target: RenderTarget, view: View, gpu_meshes,
                       opaque, lights: list[Light], shading: str, specular: str) -> None:
        """Per light: count its volumes in the stencil, then add that light alone where the
        count is 0, with the program variant compiled for that one light (the others would
        be evaluated and multiplied by S_i = 0: the same sum, m times the shading work)."""
        shadows = self.shadow_volumes
        shadows.drop_lights_from(len(lights))
        method = scene.render.shadow_method
        for index, light in enumerate(lights):
            volumes = shadows.volumes(scene, gpu_meshes, index, light)
            # the first light counts on the stencil the frame's clear left at 0 (pass 1; the
            # ambient pass writes no stencil)
            passes = self._stencil_for_light(scene, target, view, volumes, method, light,
                                             stencil_clean=index == 0)
            for ref, lit in passes:
                self.ctx.enable_only(moderngl.DEPTH_TEST | moderngl.BLEND)
                self.ctx.blend_func = moderngl.ONE, moderngl.ONE
                self.ctx.depth_func = "<="
                shadows.lit_where_zero(ref)
                self.use_lights([lit], specular, terminator=True)
                for variant in self.variants(shading):
                    self.set_frame_uniforms(variant, scene, view, specular, [lit],
                                            ambient_on=0.0)
                self.draw_objects(scene, opaque, shading, terminator=True)
                for variant in self.variants(shading):   # this light's variant: fade off again
                    set_uniform(variant, "u_terminator", 0.0)
        shadows.stencil_off()
        self.use_lights(lights, specular)
        self.ctx.depth_func = "<"
        self.ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA  # the default
        target.fbo.depth_mask = True
        target.fbo.use()
        for variant in self.variants(shading):
            self.set_frame_lights(variant, lights, ambient_on=1.0)

    def _stencil_for_light(self, scene: Scene, target: RenderTarget, view: View, volumes,
                           method: str, light: Light,
                           stencil_clean: bool = False) -> list[tuple[int, Light]]:
        """Fill the stencil for one light; return its lit passes as (stencil value, light).

        Opaque casters only: the volume count, one pass where it is 0 (S_i = 1). With
        transparent casters (kt > 0) S_i is kt-filtered as in the ray tracer: each of the
        first FILTER_SLOTS gets a flag bit where the surface is inside its volume, the opaque
        casters count in the low bits, and one pass per combination of flags adds the light
        with Ip scaled by the product of those casters' transmittance: the shadow_filter
        kt Ot (kt alone, interpolated model) once for an open caster (a pane), squared for a
        closed one (the shadow ray enters and leaves it).
        """
        from itertools import product

        from shadelab.raster.shadows import COUNTER_MASK, FILTER_SLOTS, filter_bit
        from shadelab.shading.reference import shadow_filter

        shadows = self.shadow_volumes
        clear = [v for v in volumes
                 if is_transparent(scene.materials[scene.objects[v.object_index].material])]
        if not clear:
            shadows.count(target, view, volumes, method, clear=not stencil_clean)
            return [(0, light)]
        filters = clear[:FILTER_SLOTS]       # further transparent casters cast no shadow
        opaque = [v for v in volumes if v not in clear]
        shadows.count(target, view, [], method)                  # every bit to 0
        for slot, caster in enumerate(filters):
            shadows.flag_inside(target, view, caster, method, slot)
        shadows.count(target, view, opaque, method, field=COUNTER_MASK)
        factors = []
        for caster in filters:
            material = scene.materials[scene.objects[caster.object_index].material]
            crossings = 2 if caster.volume.method == "silhouette" else 1
            factors.append(shadow_filter(material) ** crossings)
        passes = []
        for inside in product((False, True), repeat=len(filters)):
            ref = sum(filter_bit(slot) for slot, on in enumerate(inside) if on)
            scale = np.ones(3)
            for on, factor in zip(inside, factors, strict=True):
                if on:
                    scale = scale * factor
            if scale.max() <= 0.0:
                continue                                          # fully blocked: add nothing
            passes.append((ref, replace(light, Ip=tuple(float(c) for c in
                                                          np.asarray(light.Ip) * scale))))
        return passes

    def _shadow_overlays(self, scene: Scene, target: RenderTarget, view: View, gpu_meshes,
                         lights: list[Light]) -> None:
        shadows = self.shadow_volumes
        settings = scene.render
        index = min(settings.heatmap_light, len(lights) - 1)
        volumes = shadows.volumes(scene, gpu_meshes, index, lights[index])
        if settings.stencil_heatmap:
            shadows.count(target, view, volumes, settings.shadow_method)
            shadows.heatmap()
        if settings.show_volumes:
            for i, light in enumerate(lights):
                shadows.draw_translucent(target, view,
                                         shadows.volumes(scene, gpu_meshes, i, light))
        if settings.show_silhouettes:
            for i, light in enumerate(lights):
                shadows.draw_silhouettes(view, shadows.volumes(scene, gpu_meshes, i, light))
        target.fbo.depth_mask = True
        target.fbo.use()

    def draw_objects(self, scene: Scene, gpu_meshes: list[GpuMesh], shading: str,
                     terminator: bool = False) -> None:
        """Draw each mesh with its material; ``terminator`` (the shadow-volume lit pass) turns
        on the fade of S_i where N.L nears each point's terminator threshold (u_terminator 1)
        on smooth meshes, unless the renderer is ``exact``.

        The frame's culled meshes (:meth:`cullable`: closed, wound outward, seen from outside)
        are drawn with back faces culled: every pixel a back face covers is covered nearer by
        a front face of the same mesh, so the image is the same with less fill and shading."""
        # flat: N = Ng, nothing to join
        soften = terminator and shading != "flat" and not self.exact
        culled = self._culled
        culling = False
        try:
            if not terminator:  # no per-mesh uniform: one draw per run of one material
                for run in _cull_runs(_material_runs(gpu_meshes), culled):
                    culling = self._cull(id(run[0]) in culled, culling)
                    program_name = self.use_material(scene, run[0].mesh.material, shading)
                    self.vao(self._batch(run), program_name).render(moderngl.TRIANGLES)
                return
            for gpu in gpu_meshes:
                culling = self._cull(id(gpu) in culled, culling)
                program_name = self.use_material(scene, gpu.mesh.material, shading)
                if terminator:
                    set_uniform(self.programs[program_name], "u_terminator",
                                1.0 if soften and gpu.mesh.corner_terminators.any() else 0.0)
                self.vao(gpu, program_name).render(moderngl.TRIANGLES)
        finally:
            self._cull(False, culling)

    def _cull(self, on: bool, now: bool) -> bool:
        """Switch back-face culling to ``on`` if it is not so ``now``; returns ``on``."""
        if on != now:
            if on:
                self.ctx.front_face = "ccw"
                self.ctx.cull_face = "back"
                self.ctx.enable(moderngl.CULL_FACE)
            else:
                self.ctx.disable(moderngl.CULL_FACE)
        return on

    def cullable(self, gpu: GpuMesh, scene: Scene, size: tuple[int, int]) -> bool:
        """Can the opaque mesh be drawn with its back faces culled, image unchanged? Only a
        closed, consistently wound mesh wound counter-clockwise seen from outside (memoized
        per geometry), with the eye outside its bounding box grown by the reach of the near
        plane (else the near plane could cut a front face away and show the inside: the
        Cornell room, a camera inside a sphere)."""
        outward = memoized(self._outward, gpu.key, lambda: _closed_outward(
            gpu.mesh.vertices, gpu.mesh.faces), 256)
        return outward and eye_outside(gpu.bounds, scene, size)

    def _batch(self, run: list[GpuMesh]) -> GpuMesh:
        """Consecutive meshes of one material as one buffer (copied on the GPU once, kept
        until the geometry changes): the same triangles in the same order, one draw."""
        if len(run) == 1:
            return run[0]
        key = tuple(map(id, run))
        batch = self._batches.get(key)
        if batch is None:
            vbo = self.ctx.buffer(reserve=sum(g.vbo.size for g in run))
            offset = 0
            for gpu in run:
                self.ctx.copy_buffer(vbo, gpu.vbo, gpu.vbo.size, 0, offset)
                offset += gpu.vbo.size
            bounds = _union_bounds([g.bounds for g in run])
            batch = self._batches[key] = GpuMesh(key, run[0].mesh, vbo, {}, bounds)
        return batch

    def _release_batches(self) -> None:
        for batch in self._batches.values():
            batch.release()
        self._batches.clear()

    def release(self) -> None:
        self._release_batches()
        self._bounds = None
        for gpu in self._gpu.values():
            gpu.release()
        self._gpu.clear()
        for variant in self._variants.values():
            for program in variant.values():
                program.release()
        self._variants.clear()
        self._uniforms.clear()
        self._view = self._view_key = self._matrix = None
        if self._shadows is not None:
            self._shadows.release()
            self._shadows = None
        self.textures.release()


def _chunk_fades(ctx: moderngl.Context) -> bool:
    """Whether the context's lighting chunk has the terminator fade (declares the
    ``terminator_t`` that the programs' TERMINATOR code sets): ShadeLab's own does; a student's
    copy with the TERMINATOR blocks deleted does not, and compiles without them. The includes
    are registered first, as the compile will (else a frame that starts with the lit pass saw
    none yet, or a previous render's: a fade missing, or asked of a chunk without one)."""
    gl_programs.register_includes(ctx)
    return "float terminator_t" in ctx.includes.get("lighting", "")


def _near_first(gpu_meshes: list[GpuMesh], eye: np.ndarray) -> list[GpuMesh]:
    """The meshes by the distance from ``eye`` to the farthest corner of their box, nearest
    first: what lies in front mostly draws first, and llvmpipe's early depth test then skips
    shading what it hides (a floor reaching behind a wall)."""
    def reach(gpu: GpuMesh) -> float:
        return float(np.linalg.norm(box_corners(gpu.bounds) - eye, axis=1).max())

    return sorted(gpu_meshes, key=reach)


def _material_runs(gpu_meshes: list[GpuMesh]) -> list[list[GpuMesh]]:
    """The meshes in order, cut where the material changes."""
    runs: list[list[GpuMesh]] = []
    for gpu in gpu_meshes:
        if runs and runs[-1][0].mesh.material == gpu.mesh.material:
            runs[-1].append(gpu)
        else:
            runs.append([gpu])
    return runs


def _cull_runs(runs: list[list[GpuMesh]], culled: frozenset[int]) -> list[list[GpuMesh]]:
    """The runs cut further where back-face culling (``culled``: the id() of the meshes
    drawn culled) switches on or off."""
    out: list[list[GpuMesh]] = []
    for run in runs:
        for gpu in run:
            if gpu is not run[0] and (id(out[-1][0]) in culled) == (id(gpu) in culled):
                out[-1].append(gpu)
            else:
                out.append([gpu])
    return out


def _closed_outward(vertices: np.ndarray, faces: np.ndarray) -> bool:
    """Is the mesh closed and consistently wound (:func:`closed_caster`) with its faces, as
    drawn, counter-clockwise seen from outside (a positive signed volume)?"""
    from shadelab.geometry.silhouette import closed_caster

    if len(faces) == 0 or closed_caster(vertices, faces) is None:
        return False
    tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces, dtype=np.int64)]
    tri = tri - tri.reshape(-1, 3).mean(axis=0)
    volume = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0
    return bool(volume > 0.0)


def near_reach(scene: Scene, size: tuple[int, int]) -> float:
    """The farthest the near plane's rectangle reaches from the eye: anything the near plane
    cuts away of what the image shows lies within this distance of the eye."""
    aspect = size[0] / size[1]
    tan_half = tan_half_fov_y(scene.camera, aspect)
    return scene.camera.near * math.sqrt(1.0 + tan_half * tan_half * (1.0 + aspect * aspect))


def eye_outside(bounds: np.ndarray, scene: Scene, size: tuple[int, int]) -> bool:
    """Is the eye farther than :func:`near_reach` (and a margin) from the (2, 3) box?"""
    eye = np.asarray(scene.camera.eye, dtype=np.float64)
    gap = np.maximum(np.maximum(bounds[0] - eye, eye - bounds[1]), 0.0)
    return bool(np.linalg.norm(gap) > 1.01 * near_reach(scene, size) + 1e-9)


def _union_bounds(boxes: list[np.ndarray]) -> np.ndarray | None:
    """The box around per-object (2, 3) boxes; None for an empty scene (make_view's default)."""
    if not boxes:
        return None
    stacked = np.stack(boxes)
    return np.stack([stacked[:, 0].min(axis=0), stacked[:, 1].max(axis=0)])


def diffuse_only(material: Material, terms_off: int = 0) -> bool:
    """No specular term anywhere on ``material``: ks = 0, or the term switched off
    (``terms_off``, TERM_BITS). Its lobe need not be evaluated: ks Os times it is 0."""
    return material.ks == 0.0 or bool(terms_off & TERM_BITS["specular"])


def is_transparent(material: Material) -> bool:
    """Drawn in the blended pass: the lecture's transmission coefficient kt is above 0."""
    return material.kt > 0.0


def write_light_uniforms(program: moderngl.Program, lights: list[Light],
                         shadow: list[float] | None = None) -> None:
    """Fill the ``u_light_*`` arrays of ``lighting.glsl`` (see :func:`light_uniform_arrays`)."""
    for name, array in light_uniform_arrays(lights, shadow).items():
        set_uniform_array(program, name, array)


def _material_writes(state: ProgramUniforms, packed: PackedMaterial) -> list[tuple[str, bytes]]:
    """(name, bytes) of a material's uniforms the program reads: ka, kd, ks, n, Od, Os, Le
    as they are, and for a PREMULTIPLIED program the factors lighting.glsl folds
    (:func:`shadelab.shading.packing.premultiplied_uniforms`)."""
    cache = state.cache
    writes = [(name, data) for name, data in material_uniforms(packed).items() if name in cache]
    if state.premultiplied:   # the ambient term switched off: Ia ka Od folded away
        Ia = 0.0 * state.Ia if state.terms_off & TERM_BITS["ambient"] else state.Ia
        folded = premultiplied_uniforms(packed, Ia, state.ip_s, state.ambient_on)
        if "u_ambient" in cache:
            writes.append(("u_ambient", folded["u_ambient"].tobytes()))
        for name in ("u_light_diffuse", "u_light_specular"):
            uniform = cache.program.get(name, None)
            if uniform is not None:
                array = folded[name]
                writes.append((name, array[:max(uniform.array_length, 1)].tobytes()))
    return writes
