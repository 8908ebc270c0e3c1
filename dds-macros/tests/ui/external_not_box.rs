use dds_macros::DdsType;

#[derive(DdsType)]
struct S {
    #[dds(external)]
    a: u32,
}

fn main() {}
