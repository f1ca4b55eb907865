//! Access for the tests of single kernels and stages (tests/gpu_kernels.rs,
//! gpu_precision.rs, gpu_scenes.rs, sanity.rs): run kernels alone, overwrite a buffer,
//! read one by the name of its WGSL variable, lose the device. A run uses none of it.

use super::transfer::*;
use super::*;

impl GpuSimulation {
    /// Destroys the device, as a driver reset or an unplugged GPU would (tests: a run
    /// must stop with an error, not a panic).
    #[doc(hidden)]
    pub fn destroy_device_for_test(&self) {
        self.gpu.device.destroy();
    }

    /// Sets the neighbour lists' word (`control::REBUILD`, …; tests of single kernels).
    pub fn set_list_flags(&mut self, flags: u32) {
        self.write_lists_word(flags);
        self.synced = false;
    }

    /// Overwrites the spring table (tests); the next rebuild takes its springs from it.
    pub fn upload_springs(&mut self, entries: &[Entry]) {
        let table = build_table(entries, self.params.table_mask as usize + 1);
        let buf = self.buffers.table.clone();
        self.write_buffer(&buf, &table);
        self.set_list_flags(control::REBUILD | control::TABLE_CURRENT);
    }

    /// Overwrites the lists and their springs, every candidate touching (tests).
    pub fn upload_contacts(&mut self, count: &[u32], js: &[u32], history: &[f32]) {
        let (a, b, c, d) = (
            self.buffers.contact_count.clone(),
            self.buffers.contact_j.clone(),
            self.buffers.hist_in.clone(),
            self.buffers.touching.clone(),
        );
        self.write_buffer(&a, count);
        self.write_buffer(&b, js);
        self.write_buffer(&c, history);
        self.write_buffer(&d, &vec![1u32; js.len()]);
    }

    /// Overwrites the cell counts (tests of the prefix sum).
    pub fn upload_cell_counts(&mut self, counts: &[u32]) {
        let buf = self.buffers.cell_count.clone();
        self.write_buffer(&buf, counts);
    }

    /// Reads a buffer, by the name of its WGSL variable, as u32 words (tests).
    pub fn read_u32(&self, name: &str, count: usize) -> Vec<u32> {
        let buf = self
            .buffers
            .named(name)
            .unwrap_or_else(|| panic!("unknown buffer {name}"));
        self.read_buffer(buf, 0, count)
    }

    /// Reads a buffer, by the name of its WGSL variable, as f32 words (tests).
    pub fn read_f32(&self, name: &str, count: usize) -> Vec<f32> {
        let buf = self
            .buffers
            .named(name)
            .unwrap_or_else(|| panic!("unknown buffer {name}"));
        self.read_buffer(buf, 0, count)
    }

    /// Reads the per-particle force and torque accumulators (tests).
    pub fn read_forces(&self, count: usize) -> Vec<[f32; 4]> {
        self.read_buffer(&self.buffers.force, 0, count)
    }

    /// Runs one kernel with a given number of workgroups (tests of the grid-stride
    /// loops, which must cover everything from any number of workgroups).
    pub fn run_kernel_with_groups(&mut self, k: Kernel, groups: u64) {
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            self.mark_start(&mut pass);
            self.dispatch(&mut pass, k, groups);
        }
        self.gpu.queue.submit([enc.finish()]);
        self.synced = false;
    }

    /// Runs some kernels once, in order, in one submission (tests of single stages), as
    /// in a step recorded with the rebuild stages (`STAGE_EVERY`): nothing pauses.
    pub fn run_kernels(&mut self, ks: &[Kernel]) {
        self.gpu.queue.write_buffer(
            &self.buffers.control,
            (control::STAGED * 4) as u64,
            bytemuck::bytes_of(&1u32),
        );
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            self.mark_start(&mut pass);
            for &k in ks {
                self.encode_kernel(&mut pass, k);
            }
        }
        self.gpu.queue.submit([enc.finish()]);
        self.synced = false;
    }
}
