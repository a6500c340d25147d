//! Bring your own mesh: `--mesh FILE.msh` with `--clamp`/`--drive` physical groups instead of a
//! scene, and `--vtk DIR` (a ParaView series of the run).

use anyhow::{Context, Result, bail};
use clap::Args;
use hox_scenes::{Drive, Instance, Scene};
use hox_sim::io::vtk::PvdSeries;
use std::path::PathBuf;

#[derive(Args, Clone, Debug, Default)]
pub struct MeshFileArgs {
    /// A Gmsh mesh file (MSH 4.1 or 2.2) to simulate instead of a scene: the bending scene's
    /// material and solver settings, gravity, and the clamps and drives below (docs/MESHES.md).
    #[arg(long = "mesh", value_name = "FILE.msh")]
    pub mesh_file: Option<PathBuf>,
    /// Hold a physical group of the mesh file fixed (give it again for more groups).
    #[arg(long, value_name = "GROUP")]
    pub clamp: Vec<String>,
    /// Move a physical group of the mesh file (give it again for more groups); how is set by
    /// the --drive-* options, each given once for every drive or once per drive, in order.
    #[arg(long, value_name = "GROUP")]
    pub drive: Vec<String>,
    /// Translation of a driven group, metres.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub drive_translation_m: Vec<[f64; 3]>,
    /// Rotation of a driven group, degrees, about --drive-axis through --drive-origin-m.
    #[arg(long, value_name = "DEGREES", allow_negative_numbers = true)]
    pub drive_rotation_deg: Vec<f64>,
    /// Rotation axis of a driven group (default: x).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub drive_axis: Vec<[f64; 3]>,
    /// Rotation centre of a driven group, metres (default: the centre of the group's nodes).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub drive_origin_m: Vec<[f64; 3]>,
    /// Seconds over which the drives are ramped in smoothly (then held).
    #[arg(long, value_name = "SECONDS", default_value_t = 1.0, allow_negative_numbers = true)]
    pub drive_ramp_secs: f64,
    /// Switch gravity off (a --mesh scene has gravity, -9.81 m/s² along z, by default).
    #[arg(long)]
    pub no_gravity: bool,
}

#[derive(Args, Clone, Debug, Default)]
pub struct VtkArgs {
    /// Write the run as VTK files for ParaView: DIR/NAME_000000.vtu, … (points, cells,
    /// displacement_m, von_mises_stress_pa) and DIR/NAME.pvd, the series index to open. The
    /// folder is created and checked before simulating.
    #[arg(long, value_name = "DIR")]
    pub vtk: Option<PathBuf>,
    /// Write every Nth frame only (the first and the last are always written).
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub vtk_every: u64,
}

fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let bad = || format!("'{s}' must be three finite numbers X,Y,Z, e.g. 0,0,-0.1");
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(bad());
    }
    let mut v = [0.0; 3];
    for (vi, p) in v.iter_mut().zip(parts) {
        *vi = p.parse::<f64>().map_err(|_| bad())?;
        if !vi.is_finite() {
            return Err(bad());
        }
    }
    Ok(v)
}

/// The scene `--mesh` and its options describe (None without --mesh, when none of its options
/// may be given either).
pub fn scene(args: &MeshFileArgs) -> Result<Option<Scene>> {
    let Some(path) = args.mesh_file.as_ref() else {
        let orphan = [
            ("--clamp", !args.clamp.is_empty()),
            ("--drive", !args.drive.is_empty()),
            ("--drive-translation-m", !args.drive_translation_m.is_empty()),
            ("--drive-rotation-deg", !args.drive_rotation_deg.is_empty()),
            ("--drive-axis", !args.drive_axis.is_empty()),
            ("--drive-origin-m", !args.drive_origin_m.is_empty()),
            ("--no-gravity", args.no_gravity),
        ];
        if let Some((name, _)) = orphan.iter().find(|(_, given)| *given) {
            bail!("{name} needs --mesh FILE.msh (a scene lists its own effects)");
        }
        return Ok(None);
    };
    let n = args.drive.len();
    // one value for all drives, or one per drive
    fn per_drive<T: Copy>(name: &str, values: &[T], n: usize, k: usize) -> Result<Option<T>> {
        match values.len() {
            0 => Ok(None),
            1 => Ok(Some(values[0])),
            m if m == n => Ok(Some(values[k])),
            m => bail!("--{name} is given {m} times for {n} --drive groups: give it once for all, or once per drive"),
        }
    }
    let given = !args.drive_translation_m.is_empty()
        || !args.drive_rotation_deg.is_empty()
        || !args.drive_axis.is_empty()
        || !args.drive_origin_m.is_empty();
    if n == 0 && given {
        bail!("the --drive-* options need a --drive GROUP to move");
    }
    if !(args.drive_ramp_secs.is_finite() && args.drive_ramp_secs >= 0.0) {
        bail!("--drive-ramp-secs must be finite and not negative, got {}", args.drive_ramp_secs);
    }
    let mut drives = Vec::with_capacity(n);
    for (k, group) in args.drive.iter().enumerate() {
        let rotation_deg = per_drive("drive-rotation-deg", &args.drive_rotation_deg, n, k)?.unwrap_or(0.0);
        if !rotation_deg.is_finite() {
            bail!("--drive-rotation-deg must be finite, got {rotation_deg}");
        }
        let translation_m = per_drive("drive-translation-m", &args.drive_translation_m, n, k)?.unwrap_or([0.0; 3]);
        let axis = per_drive("drive-axis", &args.drive_axis, n, k)?;
        let origin = per_drive("drive-origin-m", &args.drive_origin_m, n, k)?;
        if rotation_deg == 0.0 && translation_m == [0.0; 3] {
            bail!(
                "--drive {group}: give a --drive-translation-m or a --drive-rotation-deg (to hold the group still, use --clamp)"
            );
        }
        drives.push(Drive {
            group: group.clone(),
            translation_m,
            rotation_axis: (rotation_deg != 0.0).then(|| axis.unwrap_or([1.0, 0.0, 0.0])),
            rotation_origin_m: origin,
            rotation_deg,
            ramp_secs: args.drive_ramp_secs,
        });
    }
    Ok(Some(Scene::from_mesh_file(path, &args.clamp, &drives, !args.no_gravity)?))
}

/// Writes a run as a PVD series: frame 0 (the rest state) at creation, then every
/// `--vtk-every`th frame, and the last one.
pub struct VtkWriter {
    series: PvdSeries,
    every: u64,
    last_written: Option<u64>,
}

impl VtkWriter {
    /// The writer `args` ask for (None without --vtk), with the rest state written: an
    /// unwritable folder fails here, before any simulation.
    pub fn create(args: &VtkArgs, instance: &Instance) -> Result<Option<VtkWriter>> {
        let Some(dir) = &args.vtk else {
            if args.vtk_every != 1 {
                bail!("--vtk-every needs --vtk DIR");
            }
            return Ok(None);
        };
        if args.vtk_every == 0 {
            bail!("--vtk-every must be at least 1");
        }
        let name = sanitize(instance.scene.name());
        let series = PvdSeries::create(dir, &name).with_context(|| format!("--vtk {}", dir.display()))?;
        let mut writer = VtkWriter { series, every: args.vtk_every, last_written: None };
        writer.write(instance)?;
        Ok(Some(writer))
    }

    /// Called after every frame.
    pub fn frame(&mut self, instance: &Instance) -> Result<(), hox_scenes::SceneError> {
        if instance.sim.frames().is_multiple_of(self.every) {
            self.write(instance).map_err(|e| hox_scenes::SceneError::Simulation {
                source_name: instance.scene.source.clone(),
                message: format!("{e:#}"),
            })?;
        }
        Ok(())
    }

    /// Writes the final frame unless it was just written; returns the index file.
    pub fn finish(mut self, instance: &Instance) -> Result<PathBuf> {
        if self.last_written != Some(instance.sim.frames()) {
            self.write(instance)?;
        }
        Ok(self.series.index_path())
    }

    fn write(&mut self, instance: &Instance) -> Result<()> {
        instance.write_vtk_frame(&mut self.series)?;
        self.last_written = Some(instance.sim.frames());
        Ok(())
    }
}

/// A file-name-safe version of a scene name.
fn sanitize(name: &str) -> String {
    let s: String =
        name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect();
    if s.is_empty() { "hox".into() } else { s }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_parse_and_bad_ones_are_refused() {
        assert_eq!(parse_vec3("0, 0,-0.1").unwrap(), [0.0, 0.0, -0.1]);
        assert!(parse_vec3("1,2").is_err() && parse_vec3("1,2,x").is_err() && parse_vec3("1,2,inf").is_err());
        assert_eq!(sanitize("my beam.v2"), "my_beam_v2");
    }
}
