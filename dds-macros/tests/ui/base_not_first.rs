use dds_macros::DdsType;

#[derive(DdsType)]
struct S {
    a: u32,
    #[dds(base)]
    b: u32,
}

fn main() {}
