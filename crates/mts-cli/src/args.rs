//! What several commands take: where the mesh comes from, which LoD, and
//! the parsers that bound counts and numbers.

use anyhow::{bail, Context, Result};
use clap::builder::TypedValueParser;
use clap::Args;
use mts::mesh::generate::Generated;
use mts::mesh::io::{load, LoadOptions};
use mts::mesh::Mesh;
use mts::mesh::{CleanOptions, CleanReport};
use mts::methods::Method;
use std::path::{Path, PathBuf};

/// Where a mesh comes from: a file or a built-in generator.
#[derive(Args)]
pub struct MeshSource {
    /// OBJ, PLY, glTF (.gltf, .glb) file (or an .mts model, for the commands
    /// that read a model).
    #[arg(conflicts_with = "generated")]
    pub(crate) mesh: Option<PathBuf>,
    /// Built-in mesh NAME:SIZE, SIZE in triangles (k/M suffixes):
    /// icosphere:100k, torus:1M, grid:20k, terrain:4M. The default when no file is given.
    #[arg(long, value_name = "NAME:SIZE")]
    pub generated: Option<Generated>,
    /// Merge vertices with identical positions.
    #[arg(long)]
    pub weld: bool,
    /// Keep the vertex properties: what a file carries is kept without
    /// it (the default); a `--generated` mesh gets texture coordinates,
    /// normals and colours. Every LoD keeps every seam.
    #[arg(long, conflicts_with = "positions_only")]
    pub properties: bool,
    /// Drop the normals, texture coordinates, colours and texture that
    /// the input carries: positions only (OBJ vertices are then not split
    /// where a position has several properties).
    #[arg(long)]
    pub positions_only: bool,
    /// The most triangles the input file may ask for (polygons
    /// triangulated, strips decoded, glTF instances counted each time;
    /// three times as many vertices): a bound on the work and memory a
    /// small file can ask for. About 650 bytes a triangle to build.
    #[arg(long, value_name = "N", default_value_t = mts::mesh::io::DEFAULT_MAX_TRIANGLES as usize,
          value_parser = count_in::<1, { 1 << 32 }>, allow_negative_numbers = true)]
    pub max_triangles: usize,
}

impl MeshSource {
    /// The model to read: an `.mts` file (recognised by its magic bytes),
    /// or the model of the mesh, built first with the default options (a
    /// progress bar on large inputs).
    pub fn model(&self) -> Result<(String, mts::MtsModel)> {
        let (name, mesh) = match &self.mesh {
            Some(path) => {
                let bytes = mts::mesh::io::read_file(path)?;
                if bytes.starts_with(mts::model::format::MAGIC) {
                    let model = mts::MtsModel::from_bytes(&bytes, path)?;
                    return Ok((path.display().to_string(), model));
                }
                let (mesh, _) = mts::mesh::io::load_bytes(&bytes, path, self.load_options())
                    .context("cannot load the mesh")?;
                (path.display().to_string(), mesh)
            }
            None => {
                let (name, mesh, _) = self.load()?;
                (name, mesh)
            }
        };
        let (model, _, _) = crate::commands::build::build_with_bar(&mesh, &Default::default())?;
        Ok((name, model))
    }

    /// [`MeshSource::load`] for the demo, whose scene and thumbnails draw
    /// positions only: the input is read without its properties
    /// (`--properties` asks for them and is refused).
    pub fn load_for_scene(&self) -> Result<(String, Mesh, CleanReport)> {
        if self.properties {
            bail!("the demo draws positions only: drop --properties");
        }
        self.load_with(false)
    }

    /// Refuses `output` when it names the input file (or one of `more`):
    /// the input would be replaced by what was made from it.
    pub fn check_output(&self, output: &Path) -> Result<()> {
        check_output(
            output,
            &self.mesh.iter().map(PathBuf::as_path).collect::<Vec<_>>(),
        )
    }

    /// How the input file is read: with its properties unless
    /// `--positions-only`.
    pub fn load_options(&self) -> LoadOptions {
        self.load_options_with(!self.positions_only)
    }

    fn load_options_with(&self, properties: bool) -> LoadOptions {
        LoadOptions {
            clean: CleanOptions { weld: self.weld },
            properties,
            max_triangles: self.max_triangles as u64,
        }
    }

    /// The mesh, its name and what cleaning did: the file read with its
    /// properties (unless `--positions-only`), or the generated mesh
    /// (with properties when `--properties`).
    pub fn load(&self) -> Result<(String, Mesh, CleanReport)> {
        self.load_with(!self.positions_only)
    }

    /// [`MeshSource::load`] with `g` as the built-in mesh when neither a
    /// file nor `--generated` is given (a command whose default input is
    /// not [`Generated::DEFAULT`]).
    pub fn load_generated(&self, g: Generated) -> Result<(String, Mesh, CleanReport)> {
        self.load_or(!self.positions_only, g)
    }

    fn load_with(&self, properties: bool) -> Result<(String, Mesh, CleanReport)> {
        self.load_or(properties, Generated::DEFAULT)
    }

    fn load_or(&self, properties: bool, default: Generated) -> Result<(String, Mesh, CleanReport)> {
        let clean = CleanOptions { weld: self.weld };
        if let Some(path) = &self.mesh {
            let (mesh, report) =
                load(path, self.load_options_with(properties)).context("cannot load the mesh")?;
            Ok((path.display().to_string(), mesh, report))
        } else {
            let g = self.generated.unwrap_or(default);
            let mesh = if self.properties && properties {
                g.build_with_properties()
            } else {
                g.build()
            };
            let raw = mts::mesh::RawMesh {
                positions: mesh.positions,
                triangles: mesh.triangles,
                degenerate_in_source: 0,
                properties: mesh.properties,
            };
            let (mesh, report) = mts::mesh::clean(raw, clean, &g.to_string())?;
            Ok((format!("generated {g}"), mesh, report))
        }
    }
}

/// How a command that writes glTF stores the vertex data.
#[derive(Args, Clone, Copy, Default)]
pub struct GltfOut {
    /// Write glTF compressed as engines ship it: quantized attributes
    /// (KHR_mesh_quantization) coded with meshoptimizer's codecs
    /// (EXT_meshopt_compression), the level in the strip-like vertex-cache
    /// order the codec does best with. About gltfpack -cc's size; a .glb or
    /// .gltf output only.
    #[arg(long)]
    pub compress: bool,
    /// Write glTF quantized (KHR_mesh_quantization: 14-bit positions,
    /// 8-bit normals and colours, 12-bit texture coordinates) but not
    /// compressed, the level in vertex-cache order.
    #[arg(long, conflicts_with = "compress")]
    pub quantize: bool,
}

impl GltfOut {
    /// The encoding asked for.
    pub fn encoding(&self) -> mts::mesh::io::Encoding {
        use mts::mesh::io::Encoding;
        match (self.compress, self.quantize) {
            (true, _) => Encoding::Compressed,
            (false, true) => Encoding::Quantized,
            _ => Encoding::Plain,
        }
    }

    /// Refuses a quantized or compressed encoding for an output that is
    /// not glTF.
    pub fn check(&self, output: &std::path::Path) -> Result<()> {
        let gltf = matches!(
            mts::mesh::io::Format::detect(output, &[]),
            Ok(mts::mesh::io::Format::Gltf)
        );
        if self.encoding() != mts::mesh::io::Encoding::Plain && !gltf {
            anyhow::bail!(
                "{}: --compress and --quantize write glTF: name the output .glb or .gltf",
                output.display()
            );
        }
        Ok(())
    }
}

/// Which LoD a command reads: by number, triangle budget or share.
#[derive(Args)]
#[command(group(clap::ArgGroup::new("level").args(["lod", "triangles", "ratio"])))]
pub struct LevelArgs {
    /// The LoD (0 is the full mesh; clamped to the last).
    #[arg(allow_negative_numbers = true, long)]
    pub lod: Option<usize>,
    /// The finest LoD with at most this many triangles.
    #[arg(allow_negative_numbers = true, long)]
    pub triangles: Option<usize>,
    /// The LoD with this share of the full triangle count (0..1).
    #[arg(allow_negative_numbers = true, long)]
    pub ratio: Option<f64>,
}

impl LevelArgs {
    /// The LoD asked for in `source`'s own numbering (`None` when none
    /// was given). See [`LevelArgs::resolve_in`].
    pub fn resolve(&self, source: &dyn mts::LodSource) -> Result<Option<usize>> {
        self.resolve_in(source.max_lod(), source.triangle_count(0), |n| {
            mts::lod::lod_for_triangles(source, n)
        })
    }

    /// The LoD of an MTS model (its own triangle table; no extractor).
    pub fn resolve_model(&self, model: &mts::MtsModel) -> Result<Option<usize>> {
        self.resolve_in(model.max_lod(), model.triangle_count(0), |n| {
            model.lod_for_triangles(n)
        })
    }

    /// The LoD from `max_lod`, the full triangle count and the finest LoD
    /// within a budget: a share is the budget `ratio × full`, answered like
    /// `--triangles`; a LoD past the last is clamped.
    pub fn resolve_in(
        &self,
        max_lod: usize,
        full: usize,
        lod_for_triangles: impl Fn(usize) -> usize,
    ) -> Result<Option<usize>> {
        Ok(match (self.lod, self.triangles, self.ratio) {
            (Some(l), _, _) => Some(l.min(max_lod)),
            (_, Some(n), _) => Some(lod_for_triangles(n)),
            (_, _, Some(r)) => {
                if !(0.0..=1.0).contains(&r) {
                    bail!("--ratio must be between 0 and 1, not {r}");
                }
                Some(lod_for_triangles((r * full as f64).round() as usize))
            }
            _ => None,
        })
    }
}

/// Refuses `output` when it is one of `inputs` (the same file, whatever
/// the path): writing it would replace what the command reads.
pub(crate) fn check_output(output: &Path, inputs: &[&Path]) -> Result<()> {
    if let Some(input) = inputs.iter().find(|i| mts::output::is_same_file(output, i)) {
        bail!(
            "{}: the output is the input file {}: write to another file",
            output.display(),
            input.display()
        );
    }
    Ok(())
}

/// A count argument in `MIN..=MAX`: what clap calls for `--repeat`,
/// `--samples`, `--requests`, `--frames` and `--scene`, so that no
/// allocation or loop is sized by an absurd number, and a negative or
/// fractional one is named as such.
pub(crate) fn count_in<const MIN: u64, const MAX: u64>(
    s: &str,
) -> std::result::Result<usize, String> {
    let n: i128 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a whole number (expected {MIN} to {MAX})"))?;
    if n < i128::from(MIN) || n > i128::from(MAX) {
        return Err(format!("{n} is outside {MIN}..={MAX}"));
    }
    Ok(n as usize)
}

/// `--pixel-error`: a finite number of pixels, 0 to 1000 (0: full
/// detail).
pub(crate) fn pixel_error(s: &str) -> std::result::Result<f32, String> {
    let v: f32 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number of pixels"))?;
    if (0.0..=1000.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{v} is outside 0..=1000 pixels"))
    }
}

/// `--band-slack`: a number of at least [`mts::model::MIN_BAND_SLACK`]
/// (`inf` is one band, as `--single-band`).
pub fn band_slack(s: &str) -> std::result::Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if v >= mts::model::MIN_BAND_SLACK {
        Ok(v)
    } else {
        Err(format!(
            "{v} is below the smallest slack, {} (use --single-band for one band)",
            mts::model::MIN_BAND_SLACK
        ))
    }
}

/// A finite number of at least 0 (weights and distances).
pub fn non_negative<T: std::str::FromStr + Into<f64> + Copy>(
    s: &str,
) -> std::result::Result<T, String> {
    let v: T = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    let x: f64 = v.into();
    if x.is_finite() && x >= 0.0 {
        Ok(v)
    } else {
        Err(format!("{x} is not a finite number of at least 0"))
    }
}

/// Most timed repetitions `--repeat` takes.
pub const MAX_REPEAT: u64 = 10_000;

/// Most surface samples per side `--samples` takes (about 1 GB of points).
pub const MAX_SAMPLES: u64 = 20_000_000;

/// Most requests per sequence `compare --requests` takes.
pub const MAX_REQUESTS: u64 = 10_000_000;

/// `--method`: one of the core's methods by its name ([`Method::name`]),
/// the possible values listed in the help.
pub fn method_parser() -> impl clap::builder::TypedValueParser<Value = Method> {
    let names: Vec<&'static str> = Method::ALL.iter().map(|m| m.name()).collect();
    clap::builder::PossibleValuesParser::new(names).map(|name| {
        *Method::ALL
            .iter()
            .find(|m| m.name() == name)
            .expect("the parser admits the methods' names only")
    })
}
