//! Runs fuzz inputs through a target's check without libFuzzer (stable toolchain, debuggable):
//! `cargo run --example repro -- cdr_decode artifacts/cdr_decode/crash-...`
fn main() {
    let mut args = std::env::args().skip(1);
    let target = args.next().expect("usage: repro TARGET FILE...");
    let run: fn(&[u8]) = match target.as_str() {
        "cdr_decode" => dds_fuzz::cdr_one,
        "rtps_decode" => dds_fuzz::rtps_one,
        "idl_parse" => dds_fuzz::idl_one,
        "typelookup_decode" => dds_fuzz::typelookup_one,
        "dynamic_decode" => dds_fuzz::dynamic_one,
        "filter_parse" => dds_fuzz::filter_one,
        "durability_key" => dds_fuzz::durability_key_one,
        "shm_header" => dds_fuzz::shm_one,
        "rtps_participant" => dds_fuzz::participant_one,
        t => panic!("unknown target {t}"),
    };
    for f in args {
        let data = std::fs::read(&f).expect("readable input");
        println!("{f}: {} bytes", data.len());
        run(&data);
        println!("{f}: ok");
    }
}
