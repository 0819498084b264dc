//! Unsafe sets in the plotted plane: their projections (the points of the plane that some
//! unsafe state projects to), the same operation as for the reachable sets, so a PRS drawn
//! clear of an unsafe region is clear of it in the full state space too.
//!
//! A box projects to the rectangle of its ranges on the plotted states (unbounded where it
//! does not constrain them); a ball to a disk when both plotted states are in it, to a band
//! when one is; a half-space whose normal lies in the plane to a half-plane. The others
//! project to the whole plane and are not drawn.

use super::geometry::{clip, rectangle, Point};
use reachc_runtime::model::UnsafeShape;

/// The projection of an unsafe set.
#[derive(Clone, Debug, PartialEq)]
pub enum Region {
    /// `[x0, x1] x [y0, y1]` (ends may be infinite).
    Rect {
        /// Horizontal range.
        x: (f64, f64),
        /// Vertical range.
        y: (f64, f64),
    },
    /// A disk.
    Disk {
        /// Centre.
        center: Point,
        /// Radius.
        radius: f64,
    },
    /// `{z : normal . z >= offset}`.
    HalfPlane {
        /// Normal (not zero).
        normal: Point,
        /// Offset.
        offset: f64,
    },
}

/// Points on a disk's boundary.
const DISK_POINTS: usize = 256;

impl Region {
    /// The projection of `shape` onto the plane of states `plane`, or `None` when it is the whole
    /// plane (the set does not constrain the plotted states).
    pub fn of(shape: &UnsafeShape, plane: [usize; 2]) -> Option<Region> {
        let all = (f64::NEG_INFINITY, f64::INFINITY);
        match shape {
            UnsafeShape::Box(ranges) => {
                let range = |s: usize| {
                    ranges
                        .iter()
                        .filter(|(i, _)| *i == s)
                        .fold(all, |acc, (_, r)| (acc.0.max(r.lo), acc.1.min(r.hi)))
                };
                let (x, y) = (range(plane[0]), range(plane[1]));
                (x != all || y != all).then_some(Region::Rect { x, y })
            }
            UnsafeShape::Ball {
                states,
                center,
                radius,
            } => {
                let at = |s: usize| states.iter().position(|&i| i == s).map(|k| center[k]);
                match (at(plane[0]), at(plane[1])) {
                    (Some(cx), Some(cy)) => Some(Region::Disk {
                        center: [cx, cy],
                        radius: *radius,
                    }),
                    (Some(c), None) => Some(Region::Rect {
                        x: (c - radius, c + radius),
                        y: all,
                    }),
                    (None, Some(c)) => Some(Region::Rect {
                        x: all,
                        y: (c - radius, c + radius),
                    }),
                    (None, None) => None,
                }
            }
            UnsafeShape::HalfSpace { normal, offset } => {
                let elsewhere = normal
                    .iter()
                    .enumerate()
                    .any(|(i, &v)| v != 0.0 && !plane.contains(&i));
                let in_plane = [normal[plane[0]], normal[plane[1]]];
                (!elsewhere && in_plane != [0.0, 0.0]).then_some(Region::HalfPlane {
                    normal: in_plane,
                    offset: *offset,
                })
            }
        }
    }

    /// Its bounding box, if bounded (`(x range, y range)`).
    pub fn bounds(&self) -> Option<((f64, f64), (f64, f64))> {
        match *self {
            Region::Rect { x, y } => [x.0, x.1, y.0, y.1]
                .iter()
                .all(|v| v.is_finite())
                .then_some((x, y)),
            // (A negative radius: an empty ball, see `polygon_in`.)
            Region::Disk { radius, .. } if radius < 0.0 => None,
            Region::Disk { center, radius } => Some((
                (center[0] - radius, center[0] + radius),
                (center[1] - radius, center[1] + radius),
            )),
            Region::HalfPlane { .. } => None,
        }
    }

    /// Its part inside the view `[x0, x1] x [y0, y1]`, as a polygon (empty if none).
    pub fn polygon_in(&self, view_x: (f64, f64), view_y: (f64, f64)) -> Vec<Point> {
        let view = [
            [view_x.0, view_y.0],
            [view_x.1, view_y.0],
            [view_x.1, view_y.1],
            [view_x.0, view_y.1],
        ];
        match *self {
            Region::Rect { x, y } => {
                let cut = |a: f64, b: f64, lo: f64, hi: f64| (a.max(lo), b.min(hi));
                let (x, y) = (
                    cut(x.0, x.1, view_x.0, view_x.1),
                    cut(y.0, y.1, view_y.0, view_y.1),
                );
                if x.0 >= x.1 || y.0 >= y.1 {
                    return Vec::new();
                }
                vec![[x.0, y.0], [x.1, y.0], [x.1, y.1], [x.0, y.1]]
            }
            // A goal's ball held inside positions that share no point has a negative radius
            // (`UnsafeShape::swept`): it holds nothing.
            Region::Disk { radius, .. } if radius < 0.0 => Vec::new(),
            Region::Disk { center, radius } => {
                let disk: Vec<Point> = (0..DISK_POINTS)
                    .map(|k| {
                        let a = std::f64::consts::TAU * k as f64 / DISK_POINTS as f64;
                        [center[0] + radius * a.cos(), center[1] + radius * a.sin()]
                    })
                    .collect();
                clip(&disk, &rectangle(view_x, view_y))
            }
            Region::HalfPlane { normal, offset } => {
                clip(&view, &[([-normal[0], -normal[1]], -offset)])
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use reachc_runtime::model::Bounds;

    #[test]
    fn projections_of_unsafe_sets() {
        let inf = f64::INFINITY;
        // A box over (px, py) in the plane (py, theta): a band in py.
        let b = UnsafeShape::Box(vec![
            (0, Bounds::new(2.4, 3.4)),
            (1, Bounds::new(-0.3, 0.5)),
        ]);
        assert_eq!(
            Region::of(&b, [1, 2]),
            Some(Region::Rect {
                x: (-0.3, 0.5),
                y: (-inf, inf)
            })
        );
        assert_eq!(Region::of(&b, [2, 3]), None);
        let ball = UnsafeShape::Ball {
            states: vec![0, 1],
            center: vec![4.4, 1.9],
            radius: 0.5,
        };
        assert_eq!(
            Region::of(&ball, [1, 0]),
            Some(Region::Disk {
                center: [1.9, 4.4],
                radius: 0.5
            })
        );
        assert_eq!(
            Region::of(&ball, [2, 1]),
            Some(Region::Rect {
                x: (-inf, inf),
                y: (1.4, 2.4)
            })
        );
        // x1 - x10 >= 1 does not constrain the plane (x1, x2): every point is some state's
        // projection.
        let mut normal = vec![0.0; 10];
        normal[0] = 1.0;
        normal[9] = -1.0;
        let hs = UnsafeShape::HalfSpace {
            normal: normal.clone(),
            offset: 1.0,
        };
        assert_eq!(Region::of(&hs, [0, 1]), None);
        assert_eq!(
            Region::of(&hs, [9, 0]),
            Some(Region::HalfPlane {
                normal: [-1.0, 1.0],
                offset: 1.0
            })
        );
    }

    #[test]
    fn half_planes_and_rectangles_are_clipped_to_the_view() {
        let hp = Region::HalfPlane {
            normal: [1.0, 0.0],
            offset: 0.5,
        };
        let poly = hp.polygon_in((0.0, 1.0), (0.0, 2.0));
        assert!(poly.iter().all(|p| p[0] >= 0.5 - 1e-12), "{poly:?}");
        assert_eq!(poly.len(), 4);
        let band = Region::Rect {
            x: (f64::NEG_INFINITY, 0.25),
            y: (-1.0, 1.0),
        };
        assert_eq!(
            band.polygon_in((0.0, 1.0), (0.0, 2.0)),
            vec![[0.0, 0.0], [0.25, 0.0], [0.25, 1.0], [0.0, 1.0]]
        );
        assert!(band.polygon_in((0.5, 1.0), (0.0, 2.0)).is_empty());
        assert_eq!(band.bounds(), None);
    }
}
