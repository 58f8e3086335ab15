//! Step 6 of Sec. 5.2: the kd-tree over the shadow-map tile grid (SMTG),
//! built on the CPU top-down over its pyramid (Giegl and Wimmer 2007, *Fitted
//! virtual shadow maps*): a node is a rectangle of grid cells, fitted to the
//! cells that need shadow map at all; it becomes a tile when one shadow map
//! no larger than the limit gives every cell its predicted resolution, and is
//! otherwise split in two across its most demanding axis.

use std::collections::VecDeque;

use glam::{UVec2, Vec2};

/// The SMTG and its pyramid as read back: level 0 is the grid (`size` ×
/// `size` cells), each next level halves the side, down to 1 × 1. A cell
/// holds the finest resolution any pixel mapping there needs, along the map's
/// two axes, in texels per unit of shadow-map coordinates (0: no pixel needs
/// this cell).
#[derive(Clone, Debug, PartialEq)]
pub struct Pyramid {
    /// Side of level 0, a power of two.
    pub size: u32,
    /// Each level's cells, row-major, level 0 first.
    pub levels: Vec<Vec<Vec2>>,
}

impl Pyramid {
    /// The pyramid of `grid` (`size` × `size`, row-major), built as the GPU does: the maximum of four children.
    #[must_use]
    pub fn from_grid(size: u32, grid: Vec<Vec2>) -> Self {
        let mut levels = vec![grid];
        let mut side = size;
        while side > 1 {
            let below = &levels[levels.len() - 1];
            let half = side / 2;
            let mut level = vec![Vec2::ZERO; (half * half) as usize];
            for y in 0..half {
                for x in 0..half {
                    let at = |dx: u32, dy: u32| below[((2 * y + dy) * side + 2 * x + dx) as usize];
                    level[(y * half + x) as usize] = at(0, 0).max(at(1, 0)).max(at(0, 1)).max(at(1, 1));
                }
            }
            levels.push(level);
            side = half;
        }
        Self { size, levels }
    }

    /// Splits the concatenated levels read back from the GPU (level 0 first).
    ///
    /// # Errors
    /// A message when the data is not a pyramid of a `size` × `size` grid.
    pub fn from_levels(size: u32, data: &[Vec2]) -> Result<Self, String> {
        if !size.is_power_of_two() {
            return Err(format!("the tile grid's side {size} is not a power of two"));
        }
        let mut levels = Vec::new();
        let (mut side, mut offset) = (size, 0usize);
        loop {
            let count = (side * side) as usize;
            let level = data.get(offset..offset + count).ok_or_else(|| format!("pyramid data ends at {} values", data.len()))?;
            levels.push(level.to_vec());
            offset += count;
            if side == 1 {
                break;
            }
            side /= 2;
        }
        Ok(Self { size, levels })
    }

    /// The maximum over the cells `[min, max)` of level 0, descending only into blocks the rectangle cuts.
    #[must_use]
    pub fn range_max(&self, min: UVec2, max: UVec2) -> Vec2 {
        self.visit(self.levels.len() - 1, UVec2::ZERO, min, max)
    }

    fn visit(&self, level: usize, block: UVec2, min: UVec2, max: UVec2) -> Vec2 {
        let span = 1u32 << level;
        let (low, high) = (block * span, block * span + UVec2::splat(span));
        if high.x <= min.x || high.y <= min.y || low.x >= max.x || low.y >= max.y {
            return Vec2::ZERO;
        }
        let side = self.size >> level;
        let value = self.levels[level][(block.y * side + block.x) as usize];
        // Inside the rectangle, or nothing needed anywhere below: the pyramid answers at once.
        if (low.cmpge(min).all() && high.cmple(max).all()) || value == Vec2::ZERO || level == 0 {
            return value;
        }
        let mut out = Vec2::ZERO;
        for child in [UVec2::new(0, 0), UVec2::new(1, 0), UVec2::new(0, 1), UVec2::new(1, 1)] {
            out = out.max(self.visit(level - 1, block * 2 + child, min, max));
        }
        out
    }

    /// The smallest rectangle of level-0 cells inside `[min, max)` that holds every cell needing something, if any.
    #[must_use]
    pub fn fitted(&self, min: UVec2, max: UVec2) -> Option<(UVec2, UVec2)> {
        let mut bounds: Option<(UVec2, UVec2)> = None;
        self.fit_visit(self.levels.len() - 1, UVec2::ZERO, (min, max), &mut bounds);
        bounds
    }

    fn fit_visit(&self, level: usize, block: UVec2, (min, max): (UVec2, UVec2), bounds: &mut Option<(UVec2, UVec2)>) {
        let span = 1u32 << level;
        let (low, high) = (block * span, block * span + UVec2::splat(span));
        if high.x <= min.x || high.y <= min.y || low.x >= max.x || low.y >= max.y {
            return;
        }
        let side = self.size >> level;
        if self.levels[level][(block.y * side + block.x) as usize] == Vec2::ZERO {
            return;
        }
        if level == 0 {
            let cell = (block, block + UVec2::ONE);
            *bounds = Some(bounds.map_or(cell, |(a, b)| (a.min(cell.0), b.max(cell.1))));
            return;
        }
        for child in [UVec2::new(0, 0), UVec2::new(1, 0), UVec2::new(0, 1), UVec2::new(1, 1)] {
            self.fit_visit(level - 1, block * 2 + child, (min, max), bounds);
        }
    }
}

/// One virtual shadow map tile: a rectangle of the light frame's shadow-map
/// coordinates and the resolution its shadow map is rendered at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tile {
    /// Smallest shadow-map coordinates covered.
    pub uv_min: Vec2,
    /// Largest shadow-map coordinates covered.
    pub uv_max: Vec2,
    /// Texels of its shadow map.
    pub size: UVec2,
    /// The resolution the predictions asked for was more than the limit allowed (a single cell
    /// needing more than the largest map, or the tile cap reached).
    pub clamped: bool,
}

impl Tile {
    /// Texels across the whole light frame at this tile's resolution, along its finer axis: a
    /// single map of this side over the frame would have texels as small as this tile's.
    #[must_use]
    pub fn resolution(&self) -> f32 {
        (self.size.as_vec2() / (self.uv_max - self.uv_min).max(Vec2::splat(f32::MIN_POSITIVE))).max_element()
    }
}

/// The tiles of one frame, and whether the cap on their number was reached.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tiling {
    /// The tiles, in the order they are rendered.
    pub tiles: Vec<Tile>,
    /// The cap on the number of tiles was reached: some tiles got less resolution than predicted.
    pub cap_reached: bool,
}

/// Smallest side a tile's map is given, texels.
pub const MIN_TILE_SIZE: u32 = 8;

/// Builds the kd-tree top-down and returns its leaves: every node is first
/// fitted to the cells that need a map; it is a leaf when one map of at most
/// `max_tile` texels a side meets its finest requirement; otherwise it is
/// split at the middle of its longest side in demanded texels. At most
/// `max_tiles` leaves: past the cap, nodes become leaves at `max_tile`, with
/// less resolution than predicted (reported), so that the cost stays bounded
/// whatever the prediction asks.
#[must_use]
pub fn tile(pyramid: &Pyramid, max_tile: u32, max_tiles: usize) -> Tiling {
    let cell = 1.0 / pyramid.size as f32;
    let mut tiling = Tiling::default();
    let mut queue: VecDeque<(UVec2, UVec2)> = VecDeque::new();
    queue.extend(pyramid.fitted(UVec2::ZERO, UVec2::splat(pyramid.size)));
    while let Some((min, max)) = queue.pop_front() {
        let extent = (max - min).as_vec2() * cell;
        let needed = pyramid.range_max(min, max) * extent;
        let fits = needed.x <= max_tile as f32 && needed.y <= max_tile as f32;
        let splittable = (max - min).cmpgt(UVec2::ONE).any();
        let full = tiling.tiles.len() + queue.len() + 2 > max_tiles.max(1);
        if fits || !splittable || full {
            let size = needed.ceil().as_uvec2().clamp(UVec2::splat(MIN_TILE_SIZE), UVec2::splat(max_tile.max(MIN_TILE_SIZE)));
            tiling.cap_reached |= !fits && splittable;
            tiling.tiles.push(Tile { uv_min: min.as_vec2() * cell, uv_max: max.as_vec2() * cell, size, clamped: !fits });
            continue;
        }
        // Split across the axis that most exceeds the limit (one that can still be split).
        let ratio = needed / max_tile as f32;
        let along_x = (max.x - min.x > 1) && (ratio.x >= ratio.y || max.y - min.y <= 1);
        let (first, second) = if along_x {
            let middle = (min.x + max.x) / 2;
            ((min, UVec2::new(middle, max.y)), (UVec2::new(middle, min.y), max))
        } else {
            let middle = (min.y + max.y) / 2;
            ((min, UVec2::new(max.x, middle)), (UVec2::new(min.x, middle), max))
        };
        for (low, high) in [first, second] {
            queue.extend(pyramid.fitted(low, high));
        }
    }
    tiling
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(size: u32, cells: &[(u32, u32, f32)]) -> Pyramid {
        let mut values = vec![Vec2::ZERO; (size * size) as usize];
        for &(x, y, resolution) in cells {
            values[(y * size + x) as usize] = Vec2::splat(resolution);
        }
        Pyramid::from_grid(size, values)
    }

    #[test]
    fn the_pyramid_answers_range_maxima_and_fits() {
        let pyramid = grid(8, &[(1, 2, 5.0), (6, 6, 9.0)]);
        assert_eq!(pyramid.levels.len(), 4);
        assert_eq!(pyramid.levels[3][0], Vec2::splat(9.0));
        assert_eq!(pyramid.range_max(UVec2::ZERO, UVec2::splat(4)), Vec2::splat(5.0));
        assert_eq!(pyramid.range_max(UVec2::new(2, 0), UVec2::new(8, 6)), Vec2::ZERO);
        assert_eq!(pyramid.fitted(UVec2::ZERO, UVec2::splat(8)), Some((UVec2::new(1, 2), UVec2::new(7, 7))));
        assert_eq!(pyramid.fitted(UVec2::new(2, 0), UVec2::new(8, 6)), None);
        let flat: Vec<Vec2> = pyramid.levels.iter().flatten().copied().collect();
        assert_eq!(Pyramid::from_levels(8, &flat).unwrap(), pyramid);
        assert!(Pyramid::from_levels(8, &flat[..10]).is_err());
    }

    #[test]
    fn a_tiles_resolution_is_its_finer_axis_over_the_whole_frame() {
        // 100 texels over a quarter of the frame along u (400 across it), 50 over all of it along v.
        let tile = Tile { uv_min: Vec2::new(0.25, 0.0), uv_max: Vec2::new(0.5, 1.0), size: UVec2::new(100, 50), clamped: false };
        assert_eq!(tile.resolution(), 400.0);
    }

    #[test]
    fn nothing_needed_gives_no_tile() {
        let tiling = tile(&grid(16, &[]), 4096, 64);
        assert!(tiling.tiles.is_empty() && !tiling.cap_reached);
    }

    #[test]
    fn a_modest_requirement_is_one_fitted_tile() {
        // Cells (2..4, 3..5) of a 16-grid need 1,000 texels per unit: 2/16 of the map → 125 texels.
        let tiling = tile(&grid(16, &[(2, 3, 1000.0), (3, 4, 1000.0)]), 4096, 64);
        assert_eq!(tiling.tiles.len(), 1);
        let tile = tiling.tiles[0];
        assert_eq!((tile.uv_min, tile.uv_max), (Vec2::new(2.0, 3.0) / 16.0, Vec2::new(4.0, 5.0) / 16.0));
        assert_eq!(tile.size, UVec2::splat(125));
        assert!(!tile.clamped);
    }

    #[test]
    fn a_demanding_grid_splits_until_every_tile_fits() {
        // Everything needs 16,384 texels per unit: four times the largest map, so 4 × 4 tiles.
        let everything: Vec<(u32, u32, f32)> = (0..16).flat_map(|y| (0..16).map(move |x| (x, y, 16384.0))).collect();
        let tiling = tile(&grid(16, &everything), 4096, 64);
        assert_eq!(tiling.tiles.len(), 16);
        assert!(tiling.tiles.iter().all(|t| t.size == UVec2::splat(4096) && !t.clamped));
        let area: f32 = tiling.tiles.iter().map(|t| (t.uv_max - t.uv_min).x * (t.uv_max - t.uv_min).y).sum();
        assert!((area - 1.0).abs() < 1e-6, "the tiles cover the map once: {area}");
        // A cap of 4 stops the splitting: four tiles of the largest size, flagged.
        let capped = tile(&grid(16, &everything), 4096, 4);
        assert!(capped.cap_reached && capped.tiles.len() <= 4);
        assert!(capped.tiles.iter().all(|t| t.size.max_element() <= 4096));
    }

    #[test]
    fn a_cell_needing_more_than_the_largest_map_is_clamped() {
        let tiling = tile(&grid(4, &[(0, 0, 1e9)]), 2048, 64);
        assert_eq!(tiling.tiles.len(), 1);
        assert!(tiling.tiles[0].clamped && tiling.tiles[0].size == UVec2::splat(2048));
        assert!(!tiling.cap_reached, "a single cell cannot be split: not the cap");
    }
}
