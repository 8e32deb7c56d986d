"""The public names of ``frustum.geometry``, each once: ``lazy_loader.attach_stub`` loads them on first use from this
stub, and editors and type checkers read it."""

from . import (
    curves as curves,
    mesh as mesh,
    polyline as polyline,
    primitives as primitives,
    quadrics as quadrics,
    surfaces as surfaces,
)
from .csg import (
    difference as difference,
    intersection as intersection,
    union as union,
)
from .curves import (
    M_B as M_B,
    M_H as M_H,
    BSpline as BSpline,
    BezierCurve as BezierCurve,
    Continuity as Continuity,
    CubicSpline as CubicSpline,
    HermiteCurve as HermiteCurve,
    NURBSCurve as NURBSCurve,
    PiecewiseBezier as PiecewiseBezier,
    bernstein as bernstein,
    bezier_matrix_form as bezier_matrix_form,
    cardinal_spline as cardinal_spline,
    catmull_rom as catmull_rom,
    continuity as continuity,
    cox_de_boor as cox_de_boor,
    hermite_blending as hermite_blending,
    open_uniform_knots as open_uniform_knots,
)
from .dimension import (
    BoxCounting as BoxCounting,
    box_counting_dimension as box_counting_dimension,
)
from .escape_time import (
    escape_time_colors as escape_time_colors,
    julia as julia,
    mandelbrot as mandelbrot,
    quaternion_julia as quaternion_julia,
    quaternion_julia_mesh as quaternion_julia_mesh,
)
from .fractals import (
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
from .io import (
    SUPPORTED_SUFFIXES as SUPPORTED_SUFFIXES,
    MeshPart as MeshPart,
    load as load,
    load_parts as load_parts,
)
from .lsystem import (
    CLASSIC_LSYSTEMS as CLASSIC_LSYSTEMS,
    LSystem as LSystem,
    TurtlePath as TurtlePath,
    interpret as interpret,
    parse_rules as parse_rules,
    tube_mesh as tube_mesh,
)
from .mesh import (
    Mesh as Mesh,
)
from .octree import (
    TEXTBOOK_OCTANTS as TEXTBOOK_OCTANTS,
    Octree as Octree,
    OctreeHits as OctreeHits,
)
from .points import (
    PointCloud as PointCloud,
    load_points as load_points,
)
from .polyline import (
    Polyline as Polyline,
)
from .primitives import (
    arrow as arrow,
    axes as axes,
    box as box,
    cone as cone,
    cylinder as cylinder,
    disk as disk,
    grid as grid,
    icosphere as icosphere,
    plane as plane,
    torus as torus,
    uv_sphere as uv_sphere,
)
from .quadrics import (
    ellipsoid as ellipsoid,
    ellipsoid_implicit as ellipsoid_implicit,
    sphere as sphere,
    sphere_implicit as sphere_implicit,
    superellipse as superellipse,
    superellipse_implicit as superellipse_implicit,
    superellipsoid as superellipsoid,
    superellipsoid_implicit as superellipsoid_implicit,
    supertoroid as supertoroid,
    supertoroid_implicit as supertoroid_implicit,
)
from .splats import (
    GaussianSplats as GaussianSplats,
)
from .surfaces import (
    BSplineSurface as BSplineSurface,
    BezierSurface as BezierSurface,
    NURBSSurface as NURBSSurface,
)
from .teapot import (
    BezierPatchSet as BezierPatchSet,
    teacup as teacup,
    teapot as teapot,
    teaspoon as teaspoon,
)
from .volume import (
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
