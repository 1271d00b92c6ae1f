MODULE ZeroLength
    ! Moves that go nowhere: the same target twice, blended and stopped.
    CONST robtarget pA := [[375, 0, 540], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pB := [[300, 150, 400], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        MoveJ pA, v1000, fine, tool0;
        MoveL pA, v200, z10, tool0;
        MoveJ pA, v1000, z50, tool0;
        MoveL pB, v500, fine, tool0;
        MoveL pB, v500, fine, tool0;
    ENDPROC
ENDMODULE
