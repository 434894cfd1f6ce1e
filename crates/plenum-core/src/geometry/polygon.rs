//! Planar polygons, convex or concave, given as a vertex loop.
//!
//! The lecture's steps: intersect the supporting plane, then decide whether the point lies
//! inside by projecting onto the coordinate plane where the polygon has the largest area and
//! counting edge crossings of a ray from the point (the even–odd rule; Haines, "Point in
//! Polygon Strategies", Graphics Gems IV).

use super::{plane_distance, project_onto_plane, HitRecord, SurfaceGeometry};
use crate::math::{Bounds3, Ray, Vec3};

#[derive(Clone, Debug, PartialEq)]
pub struct Polygon {
    vertices: Vec<Vec3>,
    /// Unit normal, by Newell's method: counter-clockwise vertices seen from its tip.
    normal: Vec3,
    /// Plane offset: normal·p = dist for points p of the plane.
    dist: f64,
    /// The two axes kept when projecting to 2-D.
    axes: (usize, usize),
    projected: Vec<[f64; 2]>,
    tangent_s: Vec3,
    tangent_t: Vec3,
}

/// Why a vertex list is not a polygon.
#[derive(Clone, Debug, PartialEq)]
pub enum PolygonError {
    TooFewVertices(usize),
    ZeroArea,
    /// The largest distance of a vertex from the best-fit plane, relative to the polygon size.
    NotPlanar(f64),
}

impl std::fmt::Display for PolygonError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PolygonError::TooFewVertices(n) => {
                write!(f, "a polygon needs at least 3 vertices, found {n}")
            }
            PolygonError::ZeroArea => write!(f, "the polygon has zero area"),
            PolygonError::NotPlanar(d) => write!(
                f,
                "the vertices are not coplanar (one lies {d:.3e} of the polygon's size off its plane)"
            ),
        }
    }
}

impl Polygon {
    pub fn new(vertices: Vec<Vec3>) -> Result<Polygon, PolygonError> {
        if vertices.len() < 3 {
            return Err(PolygonError::TooFewVertices(vertices.len()));
        }
        let area_vector = newell_normal(&vertices);
        let size = Bounds3::from_points(vertices.iter().copied())
            .diagonal()
            .length();
        // Compared as area/size against size, so huge coordinates do not overflow.
        if size.is_nan() || size <= 0.0 || area_vector.length() / size <= 1e-12 * size {
            return Err(PolygonError::ZeroArea);
        }
        let normal = area_vector.normalized();
        let centroid = vertices.iter().fold(Vec3::ZERO, |a, &v| a + v) / vertices.len() as f64;
        let dist = normal.dot(centroid);
        let off_plane = vertices
            .iter()
            .map(|v| (normal.dot(*v) - dist).abs())
            .fold(0.0, f64::max);
        if off_plane > 1e-6 * size {
            return Err(PolygonError::NotPlanar(off_plane / size));
        }
        let axes = match normal.max_abs_axis() {
            0 => (1, 2),
            1 => (2, 0),
            _ => (0, 1),
        };
        let projected = vertices.iter().map(|v| [v[axes.0], v[axes.1]]).collect();
        // Texture axis along the first edge of non-zero length (a polygon has one).
        let tangent_s = (1..vertices.len())
            .map(|i| vertices[i] - vertices[i - 1])
            .find(|e| e.length_squared() > 0.0)
            .unwrap_or(Vec3::X)
            .normalized();
        let tangent_t = normal.cross(tangent_s);
        Ok(Polygon {
            vertices,
            normal,
            dist,
            axes,
            projected,
            tangent_s,
            tangent_t,
        })
    }

    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    pub fn bounds(&self) -> Bounds3 {
        Bounds3::from_points(self.vertices.iter().copied())
    }

    /// The distance to the supporting plane, when the ray crosses it in (0, t_max).
    pub fn plane_hit(&self, ray: &Ray, t_max: f64) -> Option<f64> {
        plane_distance(ray, self.normal, self.dist, t_max)
    }

    /// Even–odd crossings test of a point of the plane, in the projection.
    pub fn contains(&self, p: Vec3) -> bool {
        let (px, py) = (p[self.axes.0], p[self.axes.1]);
        let mut inside = false;
        let n = self.projected.len();
        for i in 0..n {
            let a = self.projected[i];
            let b = self.projected[(i + 1) % n];
            if (a[1] > py) != (b[1] > py) {
                let x = a[0] + (py - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
                if px < x {
                    inside = !inside;
                }
            }
        }
        inside
    }

    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        let t = self.plane_hit(ray, t_max)?;
        self.contains(ray.at(t)).then_some(HitRecord {
            t,
            u: 0.0,
            v: 0.0,
            part: 0,
        })
    }

    pub fn surface(&self, ray: &Ray, hit: &HitRecord) -> SurfaceGeometry {
        let (p, p_error) = project_onto_plane(ray, hit.t, self.normal, self.dist);
        let d = p - self.vertices[0];
        let uv = [d.dot(self.tangent_s), d.dot(self.tangent_t)];
        SurfaceGeometry::flat(p, p_error, self.normal, uv)
    }

    /// The unit axes of (u, v).
    pub fn uv_derivatives(&self) -> [Vec3; 2] {
        [self.tangent_s, self.tangent_t]
    }
}

impl Polygon {
    /// The polygon's area as triangles wound counter-clockwise about its normal, covering
    /// exactly what the even–odd test calls inside, for concave and self-crossing loops
    /// alike (a fan from one vertex covers a concave polygon's notch). In the projection,
    /// the plane is cut into slabs at every vertex and every crossing of two edges; within
    /// a slab no two edges cross, so sorted by x the edges pair off, inside between the
    /// first and second, the third and fourth, …, each pair a trapezoid of two triangles.
    pub fn triangles(&self) -> Vec<[Vec3; 3]> {
        type Edge = ([f64; 2], [f64; 2]);
        let n = self.projected.len();
        let edges: Vec<Edge> = (0..n)
            .map(|i| (self.projected[i], self.projected[(i + 1) % n]))
            .filter(|(a, b)| a[1] != b[1])
            .collect();
        let mut ys: Vec<f64> = self.projected.iter().map(|p| p[1]).collect();
        for (i, e) in edges.iter().enumerate() {
            for f in &edges[i + 1..] {
                ys.extend(crossing_y(*e, *f));
            }
        }
        ys.sort_by(f64::total_cmp);
        ys.dedup();
        let x_at = |(a, b): Edge, y: f64| a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
        // Back from the projection onto the plane: normal·p = dist.
        let (a, b) = self.axes;
        let c = 3 - a - b;
        let lift = |[u, v]: [f64; 2]| {
            let mut p = [0.0; 3];
            p[a] = u;
            p[b] = v;
            p[c] = (self.dist - self.normal[a] * u - self.normal[b] * v) / self.normal[c];
            Vec3::new(p[0], p[1], p[2])
        };
        let size = Bounds3::from_points(self.projected.iter().map(|p| Vec3::new(p[0], p[1], 0.0)))
            .diagonal()
            .length();
        let tiny = 1e-12 * size * size;
        let mut triangles = Vec::new();
        for w in ys.windows(2) {
            let (y0, y1) = (w[0], w[1]);
            let middle = 0.5 * (y0 + y1);
            // The edges crossing the slab, by the same rule as `contains`.
            let mut crossing: Vec<Edge> = edges
                .iter()
                .copied()
                .filter(|(p, q)| (p[1] > middle) != (q[1] > middle))
                .collect();
            crossing.sort_by(|e, f| x_at(*e, middle).total_cmp(&x_at(*f, middle)));
            for pair in crossing.chunks_exact(2) {
                let (l, r) = (pair[0], pair[1]);
                let q = [
                    [x_at(l, y0), y0],
                    [x_at(r, y0), y0],
                    [x_at(r, y1), y1],
                    [x_at(l, y1), y1],
                ];
                for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                    let twice_area = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1])
                        - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]);
                    // Slivers of rounding where two edges meet add nothing.
                    if !(twice_area.abs() > tiny) {
                        continue;
                    }
                    let [p, q, r] = t.map(lift);
                    triangles.push(if (q - p).cross(r - p).dot(self.normal) >= 0.0 {
                        [p, q, r]
                    } else {
                        [p, r, q]
                    });
                }
            }
        }
        triangles
    }
}

/// The height at which two edges cross inside both, if they do (not at a shared end).
fn crossing_y((p, p2): ([f64; 2], [f64; 2]), (q, q2): ([f64; 2], [f64; 2])) -> Option<f64> {
    let (r, s) = ([p2[0] - p[0], p2[1] - p[1]], [q2[0] - q[0], q2[1] - q[1]]);
    let denominator = r[0] * s[1] - r[1] * s[0];
    if denominator == 0.0 {
        return None;
    }
    let d = [q[0] - p[0], q[1] - p[1]];
    let t = (d[0] * s[1] - d[1] * s[0]) / denominator;
    let u = (d[0] * r[1] - d[1] * r[0]) / denominator;
    (t > 0.0 && t < 1.0 && u > 0.0 && u < 1.0).then(|| p[1] + t * r[1])
}

/// Newell's method: a vector normal to the polygon whose length is twice its area, robust
/// for concave and slightly non-planar loops.
pub(crate) fn newell_normal(vertices: &[Vec3]) -> Vec3 {
    let n = vertices.len();
    (0..n).fold(Vec3::ZERO, |acc, i| {
        let a = vertices[i];
        let b = vertices[(i + 1) % n];
        acc + Vec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An L-shaped (concave) hexagon in the z = 1 plane.
    fn l_shape() -> Polygon {
        Polygon::new(vec![
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(2.0, 0.0, 1.0),
            Vec3::new(2.0, 1.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, 2.0, 1.0),
            Vec3::new(0.0, 2.0, 1.0),
        ])
        .unwrap()
    }

    #[test]
    fn concave_polygon_point_in_polygon() {
        let poly = l_shape();
        assert_eq!(poly.normal(), Vec3::Z);
        let down = |x, y| Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z);
        assert!(poly.intersect(&down(0.5, 0.5), 1e9).is_some());
        assert!(poly.intersect(&down(1.5, 0.5), 1e9).is_some());
        assert!(poly.intersect(&down(0.5, 1.5), 1e9).is_some());
        // The notch of the L.
        assert!(poly.intersect(&down(1.5, 1.5), 1e9).is_none());
        assert!(poly.intersect(&down(2.5, 0.5), 1e9).is_none());
        let hit = poly.intersect(&down(0.5, 0.5), 1e9).unwrap();
        assert!((hit.t - 4.0).abs() < 1e-15);
    }

    fn area(triangles: &[[Vec3; 3]]) -> f64 {
        triangles
            .iter()
            .map(|[p, q, r]| 0.5 * (*q - *p).cross(*r - *p).length())
            .sum()
    }

    /// The area the even–odd test calls inside, by counting a fine grid of points of the
    /// plane (a independent of the triangles), and whether every triangle lies inside.
    fn check_triangles(poly: &Polygon, grid: usize) {
        let triangles = poly.triangles();
        for t in &triangles {
            assert!(
                (t[1] - t[0]).cross(t[2] - t[0]).dot(poly.normal()) > 0.0,
                "wound about the normal"
            );
            let centroid = (t[0] + t[1] + t[2]) / 3.0;
            assert!(poly.contains(centroid), "{t:?} lies outside");
        }
        let b = poly.bounds();
        let (lo, hi) = (b.min, b.max);
        let (a0, a1) = poly.axes;
        let (w, h) = (hi[a0] - lo[a0], hi[a1] - lo[a1]);
        let mut inside = 0;
        for i in 0..grid {
            for j in 0..grid {
                let mut p = lo;
                let u = lo[a0] + (i as f64 + 0.5) / grid as f64 * w;
                let v = lo[a1] + (j as f64 + 0.5) / grid as f64 * h;
                p = match (a0, a1) {
                    (0, 1) => Vec3::new(u, v, p.z),
                    (1, 2) => Vec3::new(p.x, u, v),
                    _ => Vec3::new(v, p.y, u),
                };
                inside += usize::from(poly.contains(p));
            }
        }
        let counted = inside as f64 / (grid * grid) as f64 * w * h;
        // In projection: the triangles' projected area.
        let n = poly.normal();
        let projected = area(&triangles) * n[3 - a0 - a1].abs();
        assert!(
            (projected - counted).abs() < 4.0 * (w + h) / grid as f64 * (w.max(h)),
            "{projected} against {counted}"
        );
    }

    /// A fan from the first vertex of the L covers its notch (area 4); the triangles cover
    /// the L (area 3) and nothing else.
    #[test]
    fn triangles_cover_concave_and_self_crossing_polygons() {
        let l = l_shape();
        assert!((area(&l.triangles()) - 3.0).abs() < 1e-12);
        let l_from_notch = Polygon::new(vec![
            Vec3::new(2.0, 1.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, 2.0, 1.0),
            Vec3::new(0.0, 2.0, 1.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(2.0, 0.0, 1.0),
        ])
        .unwrap();
        assert!((area(&l_from_notch.triangles()) - 3.0).abs() < 1e-12);
        check_triangles(&l_from_notch, 400);
        // A ten-pointed star, tilted out of every coordinate plane.
        let tilt = |x: f64, y: f64| Vec3::new(x, y * 0.8, 0.3 * x + y * 0.6);
        let star: Vec<Vec3> = (0..10)
            .map(|i| {
                let a = i as f64 * std::f64::consts::PI / 5.0;
                let r = if i % 2 == 0 { 1.0 } else { 0.4 };
                tilt(r * a.cos(), r * a.sin())
            })
            .collect();
        check_triangles(&Polygon::new(star).unwrap(), 600);
        // A pentagram drawn in one stroke: its middle is outside by the even–odd rule.
        let pentagram: Vec<Vec3> = (0..5)
            .map(|i| {
                let a = (i * 2) as f64 * 2.0 * std::f64::consts::PI / 5.0;
                Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let pentagram = Polygon::new(pentagram).unwrap();
        check_triangles(&pentagram, 600);
        assert!(!pentagram.contains(Vec3::ZERO));
        // A convex face keeps its area.
        let square = Polygon::new(vec![Vec3::ZERO, Vec3::X, Vec3::X + Vec3::Y, Vec3::Y]).unwrap();
        assert!((area(&square.triangles()) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn rejects_bad_vertex_lists() {
        assert_eq!(
            Polygon::new(vec![Vec3::ZERO, Vec3::X]),
            Err(PolygonError::TooFewVertices(2))
        );
        assert_eq!(
            Polygon::new(vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0]),
            Err(PolygonError::ZeroArea)
        );
        assert!(matches!(
            Polygon::new(vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.5), Vec3::Y]),
            Err(PolygonError::NotPlanar(_))
        ));
    }
}
