use dds_macros::DdsType;

#[derive(DdsType)]
#[dds(bit_bound = 40)]
enum E {
    A,
    B,
}

fn main() {}
