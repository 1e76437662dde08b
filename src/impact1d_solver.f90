!> The run's entry (METHOD.md sections 2-6): a scene of the event method goes to the N-body
!> engine (impact1d_nbody_solver's run_nbody: classical RK4 at the user's step within a mode,
!> in-step location of the earliest event, a re-step to the event time, then impacts, Zeno
!> rest and a new mode at the event point), one of the vissim method to impact1d_vissim.
!> One engine for every number of bodies (issue 19): the tutorial's one and two bodies are
!> one scene among many.
module impact1d_solver
  use impact1d_error, only: error_type
  use impact1d_scene, only: scene_type
  use impact1d_output, only: sink_type, run_stats, start_counts
  use impact1d_vissim, only: run_vissim
  use impact1d_interrupt, only: interrupt_count
  use impact1d_nbody_solver, only: run_nbody
  implicit none
  private
  public :: run, run_stats

contains

  !> Run a scene from t = 0 to t_end, sending every dt_out sample and every event to sink
  !> (with method 'vissim', the tutorial's fixed-step scheme instead).
  subroutine run(scene, sink, stats, error, interrupt_epoch)
    type(scene_type), intent(in) :: scene
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(out) :: stats
    type(error_type), allocatable, intent(out) :: error
    !> The interrupt count its caller started with (a sweep's, for every run of it: a run
    !> its worker starts after the interrupt ends at its first checkpoint); absent or
    !> negative: the count now.
    integer, intent(in), optional :: interrupt_epoch

    stats%interrupt_epoch = interrupt_count()
    if (present(interrupt_epoch)) then
      if (interrupt_epoch >= 0) stats%interrupt_epoch = interrupt_epoch
    end if
    ! What the sink calls the events on each row; nothing counted yet.
    sink%row_names = scene%row_name
    ! (a friction contact's events are named after it: impact1d_output's class_pair_stick)
    if (scene%n_frictions > 0) sink%row_names = [scene%row_name, scene%friction_name]
    call start_counts(stats, scene%n_rows + scene%n_stops, scene%n_bodies, scene%n_frictions)
    ! The tutorial's scheme, for any number of bodies (build_scene refuses it moving grounds,
    ! the friction laws, friction between bodies and gear ratios).
    if (scene%method == 'vissim') then
      call run_vissim(scene, sink, stats, error)
      return
    end if
    call run_nbody(scene, sink, stats, error)
  end subroutine run
end module impact1d_solver
