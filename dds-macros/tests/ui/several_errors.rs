use dds_macros::DdsType;

// Every mistake is reported in one compile, not only the first.
#[derive(DdsType)]
#[dds(extensibility = "flexible", autoid = "random", bit_bound = 8)]
struct S {
    #[dds(keyy, key)]
    a: u32,
    #[dds(key)]
    b: Option<u32>,
    #[dds(optional)]
    c: u32,
    #[dds(base)]
    d: u32,
    #[dds(id = 0)]
    e: u32,
}

fn main() {}
