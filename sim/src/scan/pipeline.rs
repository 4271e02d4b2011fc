//! Frames in a pipeline for casters that make rays on a device ([`Caster::cast_beams`]): a casting
//! thread casts the next frames, several per device call, from their poses alone, while the rayon
//! pool measures the frame before and the caller (e.g. a writer thread) takes the one before that.
//! The device and the host both work all the time; the frames are the ones [`Scanner::frame`]
//! makes, in order.
//!
//! [`Caster::cast_beams`]: crate::cast::Caster::cast_beams

use glam::Affine3A;

use super::{Frame, Scanner};
use crate::cast::Hit;

/// A frame's hits, cast ahead of measuring.
pub(super) struct CastAhead {
    pub(super) hits: Vec<Option<Hit>>,
}

impl Scanner<'_> {
    /// Scans `frames` (frame indices, in the order given) and hands each to `each`; stops at the first error `each` returns and
    /// returns it. With a caster that makes rays on a device and a moving vehicle, the next frames
    /// are cast while this one is measured and handed over (module docs); otherwise frame after
    /// frame through [`Scanner::frame`]. Same frames either way.
    pub fn scan_frames<E>(
        &self,
        frames: impl IntoIterator<Item = usize>,
        mut each: impl FnMut(Frame) -> Result<(), E>,
    ) -> Result<(), E> {
        let Some(beams) = &self.beam_set else {
            for k in frames {
                each(self.frame(k))?;
            }
            return Ok(());
        };
        let n = beams.set.beams().len();
        let per_call = beams.set.frames_per_call();
        let frames: Vec<usize> = frames.into_iter().collect();
        std::thread::scope(|scope| {
            // One call's frames in flight while the previous call's are measured.
            let (sender, receiver) = std::sync::mpsc::sync_channel::<Vec<(usize, CastAhead)>>(1);
            let frames = &frames;
            // The casting thread uses no rayon pool: the caller may be a pool worker that blocks
            // on the channel, and every other worker may be blocked the same way (a dataset's
            // sequences), so work queued on the pool from here could wait for ever.
            scope.spawn(move || {
                for call in frames.chunks(per_call) {
                    let poses: Vec<Affine3A> = call.iter().flat_map(|&k| self.device_poses(beams, k)).collect();
                    let mut hits = self.caster.cast_beams(&beams.set, &poses);
                    let mut cast = Vec::with_capacity(call.len());
                    for (i, &k) in call.iter().enumerate().rev() {
                        cast.push((k, CastAhead { hits: hits.split_off(i * n) }));
                    }
                    cast.reverse();
                    // The receiver is gone when the caller stopped at an error.
                    if sender.send(cast).is_err() {
                        break;
                    }
                }
            });
            for call in receiver {
                for (k, ahead) in call {
                    each(self.frame_with(k, Some(ahead)))?;
                }
            }
            Ok(())
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::cast::Backend;
    use crate::rig::Rig;
    use crate::scan::{ScanConfig, Scanner};

    #[test]
    fn scan_frames_hands_over_the_frames_of_frame_in_order_and_stops_at_an_error() {
        let mesh = crate::scene::builtin::builtin("flat-objects").unwrap();
        let rig = Rig::preset("lux-roof-4").unwrap();
        let config = ScanConfig { seed: 1, frames: 3, speed_m_per_s: 5.0, backend: Backend::Bvh, ..Default::default() };
        let scanner = Scanner::new(&mesh, &rig, config).unwrap();
        let mut got = Vec::new();
        scanner
            .scan_frames(0..3, |f| {
                got.push(f);
                Ok::<(), ()>(())
            })
            .unwrap();
        assert_eq!(got.iter().map(|f| f.index).collect::<Vec<_>>(), [0, 1, 2]);
        let debug = |f: &crate::scan::Frame| format!("{:?}", f.cloud);
        assert_eq!(debug(&got[2]), debug(&scanner.frame(2)));
        let mut seen = 0;
        assert_eq!(
            scanner.scan_frames(0..3, |_| {
                seen += 1;
                if seen == 2 { Err("stop") } else { Ok(()) }
            }),
            Err("stop")
        );
        assert_eq!(seen, 2);
    }

    /// The production BVH behind a device's interface: whole frames, beams cast from poses (the
    /// rays made by [`crate::cast::BeamSet::rays`], not by the scanner's own arithmetic).
    struct FrameCaster(crate::cast::BvhCaster);

    impl crate::cast::Caster for FrameCaster {
        fn cast(&self, ray: &crate::cast::Ray) -> Option<crate::cast::Hit> {
            self.0.cast(ray)
        }
        fn prefers_frames(&self) -> bool {
            true
        }
    }

    #[test]
    fn moving_frames_cast_from_beams_and_poses_keep_the_agreement_contract() {
        use std::sync::Arc;
        let mesh = crate::scene::builtin::builtin("flat-objects").unwrap();
        for name in ["lux-roof-4", "os1-64-roof", "hdl64e-roof"] {
            let rig = Rig::preset(name).unwrap();
            let config =
                ScanConfig { seed: 2, frames: 3, speed_m_per_s: 8.0, yaw_rate_rad_per_s: 0.3, ..Default::default() };
            let (triangles, surfaces) = crate::scan::row::triangle_records(&mesh);
            let prepared = crate::scan::PreparedScene {
                backend: Backend::Bvh,
                triangle_count: mesh.len(),
                caster: Arc::new(FrameCaster(crate::cast::BvhCaster::new(&mesh))),
                triangles: Arc::new(triangles),
                surfaces: Arc::new(surfaces),
            };
            let beams = Scanner::with_prepared(&mesh, &rig, config.clone(), &prepared).unwrap();
            let set = &beams.beam_set.as_ref().expect("a moving rig on a frame caster casts beams").set;
            let fired: usize = beams.patterns.iter().map(|p| p.firings.iter().flatten().count()).sum();
            assert!(set.beams().len() >= fired, "{} beams for {fired} firings", set.beams().len());
            let reference = Scanner::new(&mesh, &rig, config).unwrap();
            let mut pipelined = Vec::new();
            beams
                .scan_frames(0..3, |f| {
                    pipelined.push(f);
                    Ok::<(), ()>(())
                })
                .unwrap();
            for (k, f) in pipelined.iter().enumerate() {
                let want = reference.frame(k);
                for got in [&f.cloud, &beams.frame(k).cloud] {
                    let quantum = beams.measurements().iter().map(|m| m.range_quantum_m).fold(0.0, f32::max);
                    let agreement = crate::scan::Agreement::of(&want.cloud, got, quantum).unwrap();
                    assert!(agreement.both_hit > 1000, "{agreement:?}");
                    let checked = crate::scan::AgreementContract::GPU.check(&agreement);
                    assert!(checked.is_ok(), "{name} frame {k}: {checked:?} {agreement:?}");
                }
            }
        }
    }
}
