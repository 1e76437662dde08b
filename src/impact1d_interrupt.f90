!> Ctrl-C during a run driven from Python (src/impact1d_interrupt.c says how): the flat API
!> catches SIGINT, a run notes the interrupt count it starts with, and its checkpoints (every
!> 4096 steps, where progress is shown) end it when the count has moved on.
module impact1d_interrupt
  use, intrinsic :: iso_c_binding, only: c_int
  implicit none
  private
  public :: catch_interrupts, interrupt_count

  interface
    subroutine catch_interrupts() bind(c, name='impact1d_catch_interrupts')
    end subroutine catch_interrupts
    integer(c_int) function interrupt_count() bind(c, name='impact1d_interrupt_count')
      import :: c_int
    end function interrupt_count
  end interface
end module impact1d_interrupt
