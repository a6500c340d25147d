//! The camera a recording's 3D views open with (issue #35: the stock viewer's own framing left
//! P1's clamped end out of the view). The Rust SDK 0.36.3 builds a 3D view without its eye
//! (`EyeControls3D` is a view property it does not expose), so the blueprint is made into
//! messages in memory, every 3D view is found in them by its class, and an `EyeControls3D`
//! (position and look target) is added at `view/<id>/EyeControls3D` of the same blueprint
//! before it is sent; each chart (`TimeSeries` view) gets a `PlotLegend` in a corner its curves
//! leave free at the end, not over their start.
//!
//! The eye looks at the centre of the bodies' bounding box from the front, above and to the
//! right (the direction of the app's three-quarter view), far enough that a sphere around the
//! box fits the view's height with a margin whatever the window's shape.

use hox_sim::Vec3;
use rerun::RecordingStream;
use rerun::blueprint as bp;
use rerun::external::re_sdk_types::blueprint::{archetypes::PlotLegend, components::Corner2D};
use rerun::log::LogMsg;

/// Direction from the target to the eye (normalised below): front (−y), right (+x), above (+z).
const FROM: [f64; 3] = [0.35, -1.0, 0.55];

/// Distance from the target in bounding-sphere radii: the sphere fits a 3D view's height with
/// a margin (the viewer's vertical field of view is under 60°; 2.4 radii fit one of 50°).
const RADII: f64 = 2.4;

/// Room below the rest shape for the motion, as a fraction of its longest side: a cantilever
/// under gravity swings its tip down by up to two thirds of its length (the bending beam: 0.62 m
/// of 1 m), and the rest of the box is far smaller.
const SWING: f64 = 0.35;

/// The eye (position, target) for bodies at rest within `lo`–`hi`, metres, with room for their
/// swing below.
pub fn eye_for(lo: Vec3, hi: Vec3) -> ([f32; 3], [f32; 3]) {
    let longest = (hi - lo).max();
    let lo = Vec3::new(lo.x, lo.y, lo.z - SWING * longest);
    let centre = (lo + hi) * 0.5;
    let radius = ((hi - lo).norm() * 0.5).max(1e-3);
    let dir = Vec3::new(FROM[0], FROM[1], FROM[2]).normalize();
    let eye = centre + dir * (RADII * radius);
    let f = |v: Vec3| [v.x as f32, v.y as f32, v.z as f32];
    (f(eye), f(centre))
}

/// Sends `blueprint` to `rec` (active and default), every 3D view opening with its eye on the
/// box `lo`–`hi` when one is given.
pub fn send(
    rec: &RecordingStream,
    blueprint: bp::Blueprint,
    bounds: Option<(Vec3, Vec3)>,
) -> Result<(), rerun::RecordingStreamError> {
    let activation = bp::BlueprintActivation { make_active: true, make_default: true };
    let Some((lo, hi)) = bounds else { return blueprint.send(rec, activation) };
    // every hox stream is the application "hox" (the blueprint applies to its recordings)
    let (memory, storage) = rerun::RecordingStreamBuilder::new("hox").memory()?;
    blueprint.send(&memory, activation)?;
    // a flush that fails leaves no activation command below: the blueprint is then sent as made
    let _ = memory.flush_blocking();
    let mut messages = storage.take();
    let Some(activation_at) = messages.iter().position(|m| matches!(m, LogMsg::BlueprintActivationCommand(_))) else {
        // nothing to add the eye to: send as made
        return blueprint_of_messages(rec, messages);
    };
    let LogMsg::BlueprintActivationCommand(command) = messages.remove(activation_at) else { unreachable!() };
    let store = command.blueprint_id.clone();
    messages.retain(|m| *m.store_id() == store);
    let (position, target) = eye_for(lo, hi);
    let eye = rerun::external::re_sdk_types::blueprint::archetypes::EyeControls3D::new()
        .with_position(position)
        .with_look_target(target);
    let mut extra = Vec::new();
    for m in &messages {
        let LogMsg::ArrowMsg(_, arrow) = m else { continue };
        let Ok(chunk) = rerun::log::Chunk::from_arrow_msg(arrow) else { continue };
        let path = chunk.entity_path().to_string();
        let path = path.trim_start_matches('/');
        let Some(id) = path.strip_prefix("view/").filter(|id| !id.contains('/')) else { continue };
        let text = |name: &str| -> Option<String> {
            let d = chunk.component_descriptors().find(|d| d.component.to_string().ends_with(name))?;
            chunk.iter_slices::<String>(d.component).flat_map(|v| v.into_iter()).map(|s| s.to_string()).next()
        };
        let property =
            |name: &str, archetype: &dyn rerun::AsComponents| -> Result<LogMsg, rerun::RecordingStreamError> {
                let chunk = rerun::log::Chunk::builder(format!("view/{id}/{name}"))
                    .with_archetype(rerun::log::RowId::new(), rerun::TimePoint::default(), archetype)
                    .build()?;
                Ok(LogMsg::ArrowMsg(store.clone(), chunk.to_arrow_msg()?))
            };
        match text("class_identifier").as_deref() {
            Some("3D") => extra.push(property("EyeControls3D", &eye)?),
            Some("TimeSeries") => {
                // issue #57: the legend's default corner (bottom left) covered each chart's first
                // second; the curves start there and settle low (a sag, a decaying kinetic energy)
                // or high (the elastic energy)
                let settles_high = text("display_name").is_some_and(|n| n.starts_with("elastic energy"));
                let corner = if settles_high { Corner2D::RightBottom } else { Corner2D::RightTop };
                extra.push(property("PlotLegend", &PlotLegend::new().with_corner(corner))?);
            }
            _ => {}
        }
    }
    messages.extend(extra);
    rec.send_blueprint(messages, command);
    Ok(())
}

/// The blueprint's own messages (not the memory stream's recording) recorded as they are.
fn blueprint_of_messages(rec: &RecordingStream, messages: Vec<LogMsg>) -> Result<(), rerun::RecordingStreamError> {
    use rerun::external::re_log_types::StoreKind;
    for m in messages.into_iter().filter(|m| m.store_id().kind() == StoreKind::Blueprint) {
        rec.record_msg(m);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue #57: each chart's legend sat in its default corner (bottom left), over the first
    /// second of its curves; the blueprint sent now puts it top right (bottom right for the
    /// elastic energy, which settles high).
    #[test]
    fn a_chart_s_legend_does_not_cover_its_first_second() {
        let (rec, storage) = rerun::RecordingStreamBuilder::new("hox").memory().unwrap();
        let charts = ["kinetic energy (J)", "elastic energy (J)", "probe tip: u_z (m)"];
        let views: Vec<bp::ContainerLike> = charts.iter().map(|c| bp::TimeSeriesView::new(*c).into()).collect();
        let blueprint = bp::Blueprint::new(bp::Vertical::new(views));
        send(&rec, blueprint, Some((Vec3::zeros(), Vec3::new(1.0, 0.1, 0.1)))).unwrap();
        rec.flush_blocking().unwrap();
        let mut corners = Vec::new();
        for m in storage.take() {
            let LogMsg::ArrowMsg(_, arrow) = m else { continue };
            let chunk = rerun::log::Chunk::from_arrow_msg(&arrow).unwrap();
            if chunk.entity_path().to_string().ends_with("/PlotLegend") {
                let component = PlotLegend::descriptor_corner().component;
                corners.extend(chunk.iter_component::<Corner2D>(component).flat_map(|c| c.to_vec()));
            }
        }
        corners.sort_by_key(|c| *c as u8);
        assert_eq!(corners, [Corner2D::RightTop, Corner2D::RightTop, Corner2D::RightBottom]);
    }

    #[test]
    fn the_eye_sees_the_whole_box_from_the_front_above() {
        let (eye, target) = eye_for(Vec3::new(0.0, -0.05, -0.05), Vec3::new(1.0, 0.05, 0.05));
        // the box grown 0.35 m down for the swing: centre z −0.175, diagonal √(1 + 0.01 + 0.45²)
        assert!((target[0] - 0.5).abs() < 1e-6 && target[1].abs() < 1e-6 && (target[2] + 0.175).abs() < 1e-6);
        let radius = (1.0f32 + 0.01 + 0.45 * 0.45).sqrt() / 2.0;
        let d = ((eye[0] - target[0]).powi(2) + (eye[1] - target[1]).powi(2) + (eye[2] - target[2]).powi(2)).sqrt();
        assert!((d - 2.4 * radius).abs() < 1e-4, "{d}");
        assert!(eye[1] < 0.0 && eye[2] > target[2] && eye[0] > 0.5);
    }
}
