//! The WGSL kernels compile (naga parse + validation), and the Rust twins of the shared
//! structs have the sizes and field offsets naga computes for the WGSL. Needs no GPU.

use talus::gpu::layout;
use talus::gpu::modules::MODULES;

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
    for k in talus::gpu::modules::Kernel::ALL {
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
fn every_binding_is_the_one_rust_binds() {
    // src/gpu/bindings.rs `BINDINGS` is the one list the declarations and the bind
    // groups are built from: every variable the assembled WGSL declares with a binding
    // is in it, at the same group and binding, with a type the WGSL knows, and nothing
    // else is (the plan module declares group 2 besides the others).
    let src = MODULES.iter().find(|m| m.name == "plan").unwrap().source();
    let module = parse("plan", &src);
    let mut wgsl: Vec<(String, u32, u32)> = module
        .global_variables
        .iter()
        .filter_map(|(_, v)| {
            let b = v.binding.as_ref()?;
            Some((v.name.clone().unwrap_or_default(), b.group, b.binding))
        })
        .collect();
    let mut rust: Vec<(String, u32, u32)> = talus::gpu::BINDINGS
        .iter()
        .map(|b| (b.name.to_string(), b.group, b.binding))
        .collect();
    wgsl.sort_by_key(|b| (b.1, b.2));
    rust.sort_by_key(|b| (b.1, b.2));
    assert_eq!(
        wgsl, rust,
        "the WGSL's bindings against src/gpu/buffers.rs BINDINGS"
    );
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
        // (Params is the uniform, never an empty array.)
        assert!(
            name == "Params" || size as u64 <= talus::gpu::MIN_BUFFER,
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

// The constants shared with Rust are checked by name in tests/gpu_constants.rs (issue
// 42 item 3).

#[test]
fn the_pair_hash_is_asymmetric_and_spreads_neighbours() {
    // The WGSL hash_pair is this function bit for bit (tests/gpu_functions.rs
    // `wgsl_pair_hash_is_its_rust_twin_bit_for_bit`). Here: it is not symmetric, and it
    // spreads neighbouring pairs over the table.
    assert_ne!(layout::hash_pair(1, 2), layout::hash_pair(2, 1));
    let mut seen = std::collections::HashSet::new();
    for i in 0..64 {
        for j in i + 1..i + 8 {
            seen.insert(layout::hash_pair(i, j) & 1023);
        }
    }
    assert!(seen.len() > 300, "neighbouring pairs spread over the table");
}

#[test]
fn bindings_are_declared_only_from_the_rust_list() {
    // src/gpu/bindings.rs BINDINGS is the one source: no WGSL file declares a binding by
    // hand (a stale one there would shadow or clash with the generated declaration).
    for m in MODULES {
        for part in m.parts {
            assert!(
                !part.contains("@group(") && !part.contains("@binding("),
                "a file of {}.wgsl declares a binding; add it to BINDINGS instead",
                m.name
            );
        }
    }
}

#[test]
fn each_kernel_binds_read_only_what_it_never_writes() {
    use talus::gpu::BINDINGS;
    use talus::gpu::bindings::kernel_modules;
    use talus::gpu::modules::Kernel;
    let access = |k: Kernel, name: &str| {
        let km = &kernel_modules()[&k];
        let i = BINDINGS.iter().position(|b| b.name == name).unwrap();
        match (km.touched[i], km.writable[i]) {
            (false, _) => "-",
            (true, false) => "r",
            (true, true) => "rw",
        }
    };
    let mut table = String::new();
    for k in Kernel::ALL {
        let row: Vec<String> = (BINDINGS.iter())
            .filter(|b| access(k, b.name) != "-")
            .map(|b| format!("{}:{}", b.name, access(k, b.name)))
            .collect();
        table += &format!("{k:?}: {}\n", row.join(" "));
    }
    println!("{table}");
    // The contact kernel reads the particles and the lists, and writes only the
    // candidates' results and springs.
    for name in [
        "state",
        "props",
        "corners",
        "walls",
        "contact_j",
        "contact_count",
    ] {
        assert_eq!(
            access(Kernel::ContactForcesOnly, name),
            "r",
            "contact_forces {name}"
        );
    }
    for name in ["contact_ft", "touching", "hist_in"] {
        assert_eq!(
            access(Kernel::ContactForcesOnly, name),
            "rw",
            "contact_forces {name}"
        );
    }
    // It never touches the spring table or the particles on their way to a new order.
    for name in ["table", "state_next", "sorted"] {
        assert_eq!(
            access(Kernel::ContactForcesOnly, name),
            "-",
            "contact_forces {name}"
        );
    }
    // The integrator writes the state and only reads the candidates' results.
    assert_eq!(access(Kernel::CorrectAhead, "state"), "rw");
    assert_eq!(access(Kernel::CorrectAhead, "contact_ft"), "r");
    // The rebuild's history transfer reads what the other side writes.
    assert_eq!(access(Kernel::StoreHistory, "hist_in"), "r");
    assert_eq!(access(Kernel::StoreHistory, "table"), "rw");
    assert_eq!(access(Kernel::GatherHistory, "table"), "r");
    assert_eq!(access(Kernel::GatherHistory, "hist_in"), "rw");
}
