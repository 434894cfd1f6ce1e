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
