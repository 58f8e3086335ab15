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

    /// The texels the cells `[min, max)` of level 0 need, each at its own resolution (its two axes'
    /// product over its area): what no tiling of them can go below.
    #[must_use]
    pub fn cells_texels(&self, min: UVec2, max: UVec2) -> f32 {
        let cell_area = 1.0 / (self.size as f32 * self.size as f32);
        let mut sum = 0.0;
        for y in min.y..max.y.min(self.size) {
            for x in min.x..max.x.min(self.size) {
                let resolution = self.levels[0][(y * self.size + x) as usize];
                sum += resolution.x * resolution.y * cell_area;
            }
        }
        sum
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

/// Nodes needing fewer texels than this are not split for savings: a tile costs passes of its own
/// (culling, its pyramid, a filter dispatch over the screen) whatever its size.
pub const MIN_SPLIT_TEXELS: f32 = 65_536.0;

/// The texels a node's map needs: its finest cell's resolution over its extent, per axis, rounded up
/// and clamped as tiles are.
fn needed_size(pyramid: &Pyramid, (min, max): (UVec2, UVec2), max_tile: u32) -> (Vec2, UVec2) {
    let extent = (max - min).as_vec2() / pyramid.size as f32;
    let needed = pyramid.range_max(min, max) * extent;
    let size = needed.ceil().as_uvec2().clamp(UVec2::splat(MIN_TILE_SIZE), UVec2::splat(max_tile.max(MIN_TILE_SIZE)));
    (needed, size)
}

/// The two halves of `(min, max)` split at its middle across x (or y), each fitted to the cells that
/// need a map (none, one or two nodes).
fn halves(pyramid: &Pyramid, (min, max): (UVec2, UVec2), along_x: bool) -> Vec<(UVec2, UVec2)> {
    let (first, second) = if along_x {
        let middle = (min.x + max.x) / 2;
        ((min, UVec2::new(middle, max.y)), (UVec2::new(middle, min.y), max))
    } else {
        let middle = (min.y + max.y) / 2;
        ((min, UVec2::new(max.x, middle)), (UVec2::new(min.x, middle), max))
    };
    [first, second].into_iter().filter_map(|(low, high)| pyramid.fitted(low, high)).collect()
}

/// Builds the kd-tree top-down and returns its leaves: every node is first
/// fitted to the cells that need a map; it is split at the middle of its
/// longest side in demanded texels while one map of at most `max_tile` texels
/// a side cannot meet its finest requirement (the paper, after Giegl and
/// Wimmer). A node that fits is also split, across the axis that saves more,
/// while its map has more than `split_excess` times the texels its cells
/// need each at its own resolution, if `split_excess` > 0 (not the paper's, whose tile takes its finest cell's resolution everywhere): a few
/// cells asking for fine texels (contact shadows, surfaces the light sees
/// edge-on) then refine only their own part of the map, and the filters of
/// the pixels around them, which ask for less, read coarser texels. At most
/// `max_tiles` leaves: past the cap, nodes become leaves, those that do not
/// fit at `max_tile` with less resolution than predicted (reported), so that
/// the cost stays bounded whatever the prediction asks.
#[must_use]
pub fn tile(pyramid: &Pyramid, max_tile: u32, max_tiles: usize, split_excess: f32) -> Tiling {
    let mut tiling = Tiling::default();
    let mut queue: VecDeque<(UVec2, UVec2)> = VecDeque::new();
    queue.extend(pyramid.fitted(UVec2::ZERO, UVec2::splat(pyramid.size)));
    let texels = |size: UVec2| size.x as f32 * size.y as f32;
    while let Some((min, max)) = queue.pop_front() {
        let (needed, size) = needed_size(pyramid, (min, max), max_tile);
        let fits = needed.x <= max_tile as f32 && needed.y <= max_tile as f32;
        let splittable = (max - min).cmpgt(UVec2::ONE).any();
        let full = tiling.tiles.len() + queue.len() + 2 > max_tiles.max(1);
        let children = if !splittable || full {
            None
        } else if !fits {
            // Split across the axis that most exceeds the limit (one that can still be split).
            let ratio = needed / max_tile as f32;
            let along_x = (max.x - min.x > 1) && (ratio.x >= ratio.y || max.y - min.y <= 1);
            Some(halves(pyramid, (min, max), along_x))
        } else if split_excess > 0.0 && texels(size) >= MIN_SPLIT_TEXELS && texels(size) > split_excess * pyramid.cells_texels(min, max) {
            // Split for savings, across whichever axis leaves fewer texels.
            let cost = |nodes: &Vec<(UVec2, UVec2)>| nodes.iter().map(|&node| texels(needed_size(pyramid, node, max_tile).1)).sum::<f32>();
            [true, false]
                .into_iter()
                .filter(|&along_x| if along_x { max.x - min.x > 1 } else { max.y - min.y > 1 })
                .map(|along_x| halves(pyramid, (min, max), along_x))
                .map(|nodes| (cost(&nodes), nodes))
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .map(|(_, nodes)| nodes)
        } else {
            None
        };
        match children {
            Some(nodes) => queue.extend(nodes),
            None => {
                tiling.cap_reached |= !fits && splittable;
                tiling.tiles.push(Tile {
                    uv_min: min.as_vec2() / pyramid.size as f32,
                    uv_max: max.as_vec2() / pyramid.size as f32,
                    size,
                    clamped: !fits,
                });
            }
        }
    }
    tiling
}

/// Step 6's outcome over the last frame's lights, for the diagnostics: the tiles, the texels
/// rendered into them, the largest tile, whether the cap was reached, the tiles clamped to the
/// device's limit, the finest tile's resolution, and the first 16 tiles' sizes.
pub(crate) fn tiling_diagnostics(tilings: &[Tiling]) -> Vec<(String, f64)> {
    let tiles: Vec<&Tile> = tilings.iter().flat_map(|t| &t.tiles).collect();
    let texels: f64 = tiles.iter().map(|t| f64::from(t.size.x) * f64::from(t.size.y)).sum();
    let mut out = vec![
        ("pvsm_tiles".to_owned(), tiles.len() as f64),
        ("pvsm_texels_rendered".to_owned(), texels),
        ("pvsm_largest_tile".to_owned(), tiles.iter().map(|t| f64::from(t.size.max_element())).fold(0.0, f64::max)),
        ("pvsm_tile_cap_reached".to_owned(), f64::from(u8::from(tilings.iter().any(|t| t.cap_reached)))),
        ("pvsm_clamped_tiles".to_owned(), tiles.iter().filter(|t| t.clamped).count() as f64),
        ("pvsm_finest_resolution".to_owned(), tiles.iter().map(|t| f64::from(t.resolution())).fold(0.0, f64::max)),
    ];
    for (index, tile) in tiles.iter().enumerate().take(16) {
        out.push((format!("pvsm_tile{index}_size"), f64::from(tile.size.x.max(tile.size.y))));
    }
    out
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
        let tiling = tile(&grid(16, &[]), 4096, 64, 0.0);
        assert!(tiling.tiles.is_empty() && !tiling.cap_reached);
    }

    #[test]
    fn a_modest_requirement_is_one_fitted_tile() {
        // Cells (2..4, 3..5) of a 16-grid need 1,000 texels per unit: 2/16 of the map → 125 texels.
        let tiling = tile(&grid(16, &[(2, 3, 1000.0), (3, 4, 1000.0)]), 4096, 64, 0.0);
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
        let tiling = tile(&grid(16, &everything), 4096, 64, 0.0);
        assert_eq!(tiling.tiles.len(), 16);
        assert!(tiling.tiles.iter().all(|t| t.size == UVec2::splat(4096) && !t.clamped));
        let area: f32 = tiling.tiles.iter().map(|t| (t.uv_max - t.uv_min).x * (t.uv_max - t.uv_min).y).sum();
        assert!((area - 1.0).abs() < 1e-6, "the tiles cover the map once: {area}");
        // A cap of 4 stops the splitting: four tiles of the largest size, flagged.
        let capped = tile(&grid(16, &everything), 4096, 4, 0.0);
        assert!(capped.cap_reached && capped.tiles.len() <= 4);
        assert!(capped.tiles.iter().all(|t| t.size.max_element() <= 4096));
    }

    #[test]
    fn a_few_fine_cells_refine_only_their_part_of_the_map_when_splitting_for_savings() {
        // A 64-grid whose every cell needs 512 texels per unit, but for one cell (the contact shadow)
        // needing 4,096. The paper's tree: one tile over the frame at 4,096 a side (it fits), 16.8 M
        // texels, where the cells need 512² + (4,096² - 512²)/64² = 266,176 (integers, exact in f32).
        let mut cells: Vec<(u32, u32, f32)> = (0..64).flat_map(|y| (0..64).map(move |x| (x, y, 512.0))).collect();
        cells[(20 * 64 + 37) as usize].2 = 4096.0;
        let pyramid = grid(64, &cells);
        assert_eq!(pyramid.cells_texels(UVec2::ZERO, UVec2::splat(64)), 266_176.0);
        let paper = tile(&pyramid, 4096, 64, 0.0);
        assert_eq!(paper.tiles.len(), 1);
        assert_eq!(paper.tiles[0].size, UVec2::splat(4096));
        // Splitting while a node has more than twice its cells' texels (and at least MIN_SPLIT_TEXELS):
        // the fine cell ends in a node whose map is within twice its cells' need or under
        // MIN_SPLIT_TEXELS, the rest at 512 per unit: each split halves the node holding the fine cell,
        // so the total is far under the paper's, and the tiles still cover every cell once at no
        // less than its resolution.
        let split = tile(&pyramid, 4096, 64, 2.0);
        let texels: f32 = split.tiles.iter().map(|t| t.size.x as f32 * t.size.y as f32).sum();
        assert!(split.tiles.len() > 1 && !split.cap_reached);
        assert!(texels < 0.1 * 4096.0 * 4096.0, "{texels} texels in {} tiles", split.tiles.len());
        let area: f32 = split.tiles.iter().map(|t| (t.uv_max - t.uv_min).x * (t.uv_max - t.uv_min).y).sum();
        assert!((area - 1.0).abs() < 1e-6, "the tiles cover the map once: {area}");
        for t in &split.tiles {
            let (low, high) = ((t.uv_min * 64.0).round().as_uvec2(), (t.uv_max * 64.0).round().as_uvec2());
            let needed = pyramid.range_max(low, high) * (t.uv_max - t.uv_min);
            assert!(t.size.as_vec2().cmpge(needed.floor()).all(), "{t:?} needs {needed}");
        }
    }

    #[test]
    fn a_cell_needing_more_than_the_largest_map_is_clamped() {
        let tiling = tile(&grid(4, &[(0, 0, 1e9)]), 2048, 64, 0.0);
        assert_eq!(tiling.tiles.len(), 1);
        assert!(tiling.tiles[0].clamped && tiling.tiles[0].size == UVec2::splat(2048));
        assert!(!tiling.cap_reached, "a single cell cannot be split: not the cap");
    }
}
