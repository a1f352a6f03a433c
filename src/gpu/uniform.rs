//! Typed uniform buffers: the Rust type fixes the size, so a write can never overrun it.

use std::marker::PhantomData;

use bytemuck::Pod;

pub struct UniformBuffer<T: Pod> {
    pub buffer: wgpu::Buffer,
    _type: PhantomData<T>,
}

impl<T: Pod> UniformBuffer<T> {
    pub fn new(device: &wgpu::Device, label: &str, value: &T) -> UniformBuffer<T> {
        use wgpu::util::DeviceExt;
        let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytemuck::bytes_of(value),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        UniformBuffer { buffer, _type: PhantomData }
    }

    pub fn write(&self, queue: &wgpu::Queue, value: &T) {
        queue.write_buffer(&self.buffer, 0, bytemuck::bytes_of(value));
    }

    pub fn binding(&self) -> wgpu::BindingResource<'_> {
        self.buffer.as_entire_binding()
    }
}
