#[path = "../../examples/common/insertion_paths.rs"]
mod paths;
use needle_haptics::insertion::{stacks, Insertion, InsertionConfig};
use needle_haptics::Pose;
use paths::{depth_scale, for_each_tick, PATHS};
#[test]
fn measure() {
    for stack in &stacks::ALL {
        let (mut f, mut m) = (0f32, 0f32);
        for path in PATHS.iter() {
            let mut ins = Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).unwrap();
            for_each_tick(path, depth_scale(stack), |_, p| {
                let e = ins.step(&Pose { x_mm: p[0], z_mm: p[1], theta_x_deg: p[2], theta_z_deg: p[3], depth_mm: p[4] });
                let w = e.wrench.to_array();
                f = f.max(w[0].abs() + w[1].abs() + w[2].abs());
                m = m.max(w[3].abs() + w[4].abs() + w[5].abs());
                assert!(e.flags.is_ok(), "{:?}", e);
            });
        }
        println!("{} max force sum {f} N, moment sum {m} Nmm", stack.name);
    }
}
