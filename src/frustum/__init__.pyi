"""The public names of ``frustum``, each once: ``lazy_loader.attach_stub`` loads them on first use from this
stub, and editors and type checkers read it."""

__version__: str

from . import (
    budgets as budgets,
    camera as camera,
    camera_conventions as camera_conventions,
    clipping as clipping,
    errors as errors,
    frame as frame,
    geometry as geometry,
    interop as interop,
    projection as projection,
    quaternion as quaternion,
    scene as scene,
    shading as shading,
    steps as steps,
    transforms as transforms,
)
from .batch import (
    DatasetResult as DatasetResult,
    RenderJob as RenderJob,
    ViewResult as ViewResult,
    render_dataset as render_dataset,
    render_many as render_many,
)
from .batch.randomize import (
    cameras_on_shell as cameras_on_shell,
    drop_on_plane as drop_on_plane,
    jitter_lights as jitter_lights,
    jitter_materials as jitter_materials,
)
from .visibility.bsp import (
    BSPTree as BSPTree,
)
from .visibility.depth_sort import (
    DepthOrder as DepthOrder,
    depth_sort as depth_sort,
)
from .budgets import (
    DEFAULT_BYTES as DEFAULT_BYTES,
    DEFAULT_OPERATIONS as DEFAULT_OPERATIONS,
    Budget as Budget,
    budget as budget,
    check_memory as check_memory,
    check_operations as check_operations,
    get_budget as get_budget,
    set_budget as set_budget,
)
from .camera import (
    Camera as Camera,
    PrincipalVanishingPoints as PrincipalVanishingPoints,
    Ray as Ray,
    ViewFrame as ViewFrame,
    look_at as look_at,
)
from .clipping import (
    MAX_KERNEL_PLANES as MAX_KERNEL_PLANES,
    REGION_BOTTOM as REGION_BOTTOM,
    REGION_FAR as REGION_FAR,
    REGION_LEFT as REGION_LEFT,
    REGION_NEAR as REGION_NEAR,
    REGION_RIGHT as REGION_RIGHT,
    REGION_TOP as REGION_TOP,
    VIEW_VOLUME_PLANES as VIEW_VOLUME_PLANES,
    ClippedLines as ClippedLines,
    ClippedPolygon as ClippedPolygon,
    ClippedSegment as ClippedSegment,
    ClippedTriangles as ClippedTriangles,
    clip_line as clip_line,
    clip_line_convex as clip_line_convex,
    clip_lines as clip_lines,
    clip_polygon as clip_polygon,
    clip_triangles as clip_triangles,
    inside_view_volume as inside_view_volume,
    plane_from_point_normal as plane_from_point_normal,
    region_code as region_code,
    transform_plane as transform_plane,
    trivially_accepted as trivially_accepted,
    trivially_rejected as trivially_rejected,
)
from .shading.environment import (
    EnvironmentMap as EnvironmentMap,
)
from .errors import (
    CameraError as CameraError,
    ClippingError as ClippingError,
    FrustumError as FrustumError,
    FrustumWarning as FrustumWarning,
    GeometryError as GeometryError,
    OutputError as OutputError,
    SceneFileError as SceneFileError,
    ShadingError as ShadingError,
    SimulationError as SimulationError,
    TransformError as TransformError,
)
from .frame import (
    Frame as Frame,
)
from .geometry import (
    M_B as M_B,
    M_H as M_H,
    BSpline as BSpline,
    BSplineSurface as BSplineSurface,
    BezierCurve as BezierCurve,
    BezierPatchSet as BezierPatchSet,
    BezierSurface as BezierSurface,
    Continuity as Continuity,
    CubicSpline as CubicSpline,
    HermiteCurve as HermiteCurve,
    Mesh as Mesh,
    NURBSCurve as NURBSCurve,
    NURBSSurface as NURBSSurface,
    PiecewiseBezier as PiecewiseBezier,
    Polyline as Polyline,
    arrow as arrow,
    axes as axes,
    bernstein as bernstein,
    bezier_matrix_form as bezier_matrix_form,
    box as box,
    cardinal_spline as cardinal_spline,
    catmull_rom as catmull_rom,
    cone as cone,
    continuity as continuity,
    cox_de_boor as cox_de_boor,
    cylinder as cylinder,
    disk as disk,
    ellipsoid as ellipsoid,
    grid as grid,
    hermite_blending as hermite_blending,
    icosphere as icosphere,
    open_uniform_knots as open_uniform_knots,
    plane as plane,
    sphere as sphere,
    superellipse as superellipse,
    superellipsoid as superellipsoid,
    supertoroid as supertoroid,
    teacup as teacup,
    teapot as teapot,
    teaspoon as teaspoon,
    torus as torus,
    uv_sphere as uv_sphere,
)
from .geometry.csg import (
    difference as difference,
    intersection as intersection,
    union as union,
)
from .geometry.dimension import (
    BoxCounting as BoxCounting,
    box_counting_dimension as box_counting_dimension,
)
from .geometry.escape_time import (
    escape_time_colors as escape_time_colors,
    julia as julia,
    mandelbrot as mandelbrot,
    quaternion_julia as quaternion_julia,
    quaternion_julia_mesh as quaternion_julia_mesh,
)
from .geometry.fractals import (
    DEFAULT_MAX_BYTES as DEFAULT_MAX_BYTES,
    IFS as IFS,
    barnsley_fern as barnsley_fern,
    cantor_set as cantor_set,
    fbm_terrain as fbm_terrain,
    fractal_coastline as fractal_coastline,
    heightfield_mesh as heightfield_mesh,
    hilbert_curve as hilbert_curve,
    hilbert_curve_3d as hilbert_curve_3d,
    koch_curve as koch_curve,
    koch_snowflake as koch_snowflake,
    menger_sponge as menger_sponge,
    peano_curve as peano_curve,
    sierpinski_ifs as sierpinski_ifs,
    sierpinski_tetrahedron as sierpinski_tetrahedron,
    sierpinski_triangle as sierpinski_triangle,
    similarity_dimension as similarity_dimension,
)
from .geometry.io import (
    SUPPORTED_SUFFIXES as SUPPORTED_SUFFIXES,
    MeshPart as MeshPart,
    load as load,
    load_parts as load_parts,
)
from .geometry.lsystem import (
    CLASSIC_LSYSTEMS as CLASSIC_LSYSTEMS,
    LSystem as LSystem,
    TurtlePath as TurtlePath,
    interpret as interpret,
    parse_rules as parse_rules,
    tube_mesh as tube_mesh,
)
from .geometry.points import (
    PointCloud as PointCloud,
    load_points as load_points,
)
from .geometry.splats import (
    GaussianSplats as GaussianSplats,
)
from .geometry.octree import (
    Octree as Octree,
    OctreeHits as OctreeHits,
)
from .geometry.volume import (
    TRANSFER_PRESETS as TRANSFER_PRESETS,
    VOLUME_MODES as VOLUME_MODES,
    VOLUME_SAMPLINGS as VOLUME_SAMPLINGS,
    TransferFunction as TransferFunction,
    Volume as Volume,
    blobby_volume as blobby_volume,
    fbm_cloud as fbm_cloud,
    head_phantom as head_phantom,
    quaternion_julia_volume as quaternion_julia_volume,
)
from .visibility.hidden_lines import (
    EDGE_BOUNDARY as EDGE_BOUNDARY,
    EDGE_CREASE as EDGE_CREASE,
    EDGE_KINDS as EDGE_KINDS,
    EDGE_LINE as EDGE_LINE,
    EDGE_SILHOUETTE as EDGE_SILHOUETTE,
    HiddenLines as HiddenLines,
    feature_edges as feature_edges,
    remove_hidden_lines as remove_hidden_lines,
)
from .output.animation import (
    turntable as turntable,
    write_animation as write_animation,
)
from .output.sheet import (
    DIMENSION_MODES as DIMENSION_MODES,
    PAPER_SIZES as PAPER_SIZES,
    SHEET_VIEWS as SHEET_VIEWS,
    STANDARD_SCALES as STANDARD_SCALES,
    TITLE_BLOCK_FIELDS as TITLE_BLOCK_FIELDS,
    drawing_sheet as drawing_sheet,
    scale_label as scale_label,
)
from .output.simulate import (
    simulate as simulate,
)
from .output.annotations import annotate as annotate
from .output.stereo import (
    ANAGLYPH_METHODS as ANAGLYPH_METHODS,
    STEREO_LAYOUTS as STEREO_LAYOUTS,
    anaglyph as anaglyph,
    over_under as over_under,
    render_stereo as render_stereo,
    side_by_side as side_by_side,
)
from .output.svg import (
    FILL_ORDERS as FILL_ORDERS,
    HIDDEN_STYLES as HIDDEN_STYLES,
    render_svg as render_svg,
    save_svg as save_svg,
    svg_document as svg_document,
    svg_path_from_bezier as svg_path_from_bezier,
    svg_path_from_polyline as svg_path_from_polyline,
)
from .output.svg_shadows import (
    ShadowPolygon as ShadowPolygon,
    shadow_polygons as shadow_polygons,
)
from .output.true_curves import (
    find_circles as find_circles,
)
from .projection import (
    MULTIVIEWS as MULTIVIEWS,
    Axonometric as Axonometric,
    Frustum as Frustum,
    MultiView as MultiView,
    Oblique as Oblique,
    Orthographic as Orthographic,
    Perspective as Perspective,
    Projection as Projection,
    axonometric_rotation as axonometric_rotation,
    cabinet as cabinet,
    cavalier as cavalier,
    dimetric as dimetric,
    frustum as frustum,
    general_perspective as general_perspective,
    general_perspective_steps as general_perspective_steps,
    isometric as isometric,
    multiview as multiview,
    oblique as oblique,
    oblique_from_vector as oblique_from_vector,
    oblique_normalized as oblique_normalized,
    orthographic as orthographic,
    perspective as perspective,
    perspective_onto_plane as perspective_onto_plane,
    trimetric as trimetric,
    viewport as viewport,
)
from .quaternion import (
    Quaternion as Quaternion,
    slerp as slerp,
)
from .render.radiosity import (
    RadiosityError as RadiosityError,
    RadiosityResult as RadiosityResult,
    radiosity as radiosity,
)
from .interop.trimesh import (
    render_trimesh as render_trimesh,
)
from .raster import (
    set_compile_notice as set_compile_notice,
)
from .raster._jit import (
    set_threads as set_threads,
)
from .render import (
    RENDER_METHODS as RENDER_METHODS,
    RENDER_MODES as RENDER_MODES,
    SHADING_MODES as SHADING_MODES,
    VISIBILITY_METHODS as VISIBILITY_METHODS,
    release_memory as release_memory,
    render as render,
)
from .render.raytrace import (
    RaySegment as RaySegment,
    ray_path as ray_path,
)
from .scene import (
    Node as Node,
    ParticleLayer as ParticleLayer,
    Pick as Pick,
    Placed as Placed,
    RayHits as RayHits,
    Scene as Scene,
    SceneItem as SceneItem,
    cutaway as cutaway,
    exploded as exploded,
)
from .scenefile import (
    SceneFile as SceneFile,
    explain_method as explain_method,
    explain_scene_file as explain_scene_file,
    load_scene as load_scene,
    load_scene_file as load_scene_file,
    render_examples as render_examples,
    render_scene_file as render_scene_file,
    render_view_sheet as render_view_sheet,
)
from .shading import (
    SPECULAR_MODELS as SPECULAR_MODELS,
    AmbientLight as AmbientLight,
    DepthCue as DepthCue,
    DirectionalLight as DirectionalLight,
    Light as Light,
    Material as Material,
    PointLight as PointLight,
    SpotLight as SpotLight,
    blinn_phong as blinn_phong,
    illuminate as illuminate,
    pack_lights as pack_lights,
    sun_45 as sun_45,
)
from .simulation import (
    INTEGRATORS as INTEGRATORS,
    Attractor as Attractor,
    DiskEmitter as DiskEmitter,
    Drag as Drag,
    Gravity as Gravity,
    LineEmitter as LineEmitter,
    MassSpringSystem as MassSpringSystem,
    MeshCollider as MeshCollider,
    MeshEmitter as MeshEmitter,
    ParticleSystem as ParticleSystem,
    PlaneCollider as PlaneCollider,
    PointEmitter as PointEmitter,
    SphereCollider as SphereCollider,
    SphereEmitter as SphereEmitter,
    Vortex as Vortex,
    Wind as Wind,
    cloth as cloth,
    rope as rope,
    soft_body as soft_body,
)
from .stereo import (
    StereoCamera as StereoCamera,
)
from .trace import (
    STAGE_NAMES as STAGE_NAMES,
    SegmentClipping as SegmentClipping,
    Stage as Stage,
    Trace as Trace,
    TracedPart as TracedPart,
    TriangleClipping as TriangleClipping,
    trace as trace,
)
from .transforms import (
    Step as Step,
    apply as apply,
    apply_homogeneous as apply_homogeneous,
    apply_to_directions as apply_to_directions,
    apply_to_normals as apply_to_normals,
    compose as compose,
    invert as invert,
    reflect as reflect,
    rotate as rotate,
    rotate_steps as rotate_steps,
    rotate_x as rotate_x,
    rotate_y as rotate_y,
    rotate_z as rotate_z,
    scale as scale,
    shear as shear,
    swaps_handedness as swaps_handedness,
    to_row_major as to_row_major,
    translate as translate,
)
from .viewer import (
    Viewer as Viewer,
)
from .visibility import (
    backface_mask as backface_mask,
    plane_equations as plane_equations,
    signed_window_areas as signed_window_areas,
    viewing_position as viewing_position,
)
from .visibility.octree import (
    render_octree as render_octree,
)
from .app.warmup import (
    warmup as warmup,
)
