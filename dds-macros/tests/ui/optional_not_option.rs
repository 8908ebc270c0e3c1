use dds_macros::DdsType;

#[derive(DdsType)]
struct S {
    #[dds(optional)]
    a: u32,
}

fn main() {}
