use dds_macros::DdsType;

#[derive(DdsType)]
struct S {
    a: u32,
    #[dds(key)]
    b: Option<u32>,
}

fn main() {}
